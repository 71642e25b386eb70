# Stage envelopes: drive-frequency ridge and complex amplitudes per run (jointcal.signal).

rule envelopes_run:
    input:
        record=run_record,
        runs=INGEST / "runs.csv",
    output:
        env=ENVELOPES / "{run_id}.csv",
        meta=ENVELOPES / "{run_id}.json",
    params:
        code=source_hash("envelopes.py"),
        envelopes=config["envelopes"],
    benchmark:
        RESULTS / "benchmarks" / "envelopes" / "{run_id}.tsv"
    log:
        RESULTS / "logs" / "envelopes" / "{run_id}.log",
    script:
        "../scripts/envelopes.py"


rule envelopes:
    input:
        expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
