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
