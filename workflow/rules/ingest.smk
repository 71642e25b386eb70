# Stage ingest: validate the raw-data campaign and tabulate its runs (jointcal.io).

rule ingest:
    input:
        unpack(campaign_files),
    output:
        runs=INGEST / "runs.csv",
    params:
        code=source_hash("ingest.py"),
        ingest=config["ingest"],
    benchmark:
        RESULTS / "benchmarks" / "ingest.tsv"
    log:
        RESULTS / "logs" / "ingest.log",
    script:
        "../scripts/ingest.py"
