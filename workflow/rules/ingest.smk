# Stage ingest: validate the raw-data campaign and tabulate its runs (jointcal.io).
import jointcal


rule ingest:
    input:
        unpack(campaign_files),
    output:
        runs=RESULTS / "ingest" / "runs.csv",
    params:
        version=jointcal.__version__,  # src/ edits do not rerun rules: a version bump does
        ingest=config["ingest"],
    log:
        RESULTS / "logs" / "ingest.log",
    script:
        "../scripts/ingest.py"
