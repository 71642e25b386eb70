# Shared paths and input functions of the jointcal workflow (logic lives in src/jointcal/).
import csv
import sys
from pathlib import Path

RAW_DATA = Path(config["raw_data"])
RESULTS = Path(config["results"])
MANIFEST = RAW_DATA / "manifest.csv"
if not MANIFEST.is_file():
    sys.exit(
        f"jointcal: {MANIFEST}: the campaign manifest does not exist; put the campaign "
        "(manifest.csv and run files, see raw_data/README.md) there or point to it "
        "with --config raw_data=PATH/TO/CAMPAIGN."
    )


def campaign_files(wildcards):
    """The manifest and every run file it lists (validation itself is jointcal.io's job)."""
    with open(MANIFEST, newline="", encoding="utf-8-sig") as fh:
        listed = [(r.get("file") or "").strip() for r in csv.DictReader(fh)]
    return {"manifest": str(MANIFEST), "runs": [str(RAW_DATA / f) for f in listed if f]}


def _manifest_rows():
    with open(MANIFEST, newline="", encoding="utf-8-sig") as fh:
        return [{k.strip(): (v or "").strip() for k, v in r.items()} for r in csv.DictReader(fh)]


RUN_FILES = {r["run_id"]: str(RAW_DATA / r["file"]) for r in _manifest_rows() if r.get("run_id")}
RUN_IDS = list(RUN_FILES)
ASSEMBLIES = list(dict.fromkeys(r["assembly"] for r in _manifest_rows() if r.get("assembly")))


def run_record(wildcards):
    """The raw record of one run."""
    return RUN_FILES[wildcards.run_id]


def ingest_table(wildcards):
    """The ingest stage's runs.csv when the workflow has that stage (one of calibrate + posterior only has not)."""
    from snakemake.exceptions import WorkflowError

    try:
        rules.ingest
    except (WorkflowError, AttributeError):
        return []
    return [str(RESULTS / "ingest" / "runs.csv")]
