# Stage envelopes: drive-frequency ridge and complex amplitudes per run (jointcal.measure.envelopes).
# One job for every run of the campaign: a run takes a fraction of a second, far less than a
# process's start (about 2 s of imports), so the runs share one process pool of `threads` workers;
# each run still gets its own table and metadata, and a run that fails gets its reason.

rule envelopes_runs:
    input:
        records=campaign_records,
        runs=INGEST / "runs.csv",
    output:
        env=expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
        meta=expand(ENVELOPES / "{run_id}.json", run_id=RUN_IDS),
    params:
        code=source_hash("envelopes.py"),
        envelopes=config["envelopes"],
    threads: 2
    priority: 10  # on the longest chain of jobs (before compile_kernels, which waits for it)
    benchmark:
        RESULTS / "benchmarks" / "envelopes_runs.tsv"
    log:
        RESULTS / "logs" / "envelopes.log",
    script:
        "../scripts/envelopes.py"


rule envelopes:
    input:
        rules.envelopes_runs.output.env,
