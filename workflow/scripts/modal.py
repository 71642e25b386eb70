"""Snakemake script of rule ``modal_properties``: modal_properties.csv and scatter.csv.

Every run gets a row; a run with problems gets flags and a one-sentence warning in the
log and on stderr, never a silent drop. (No ``from __future__``: see envelopes.py.)
"""
import json
import sys
from pathlib import Path

import pandas as pd

from jointcal._checks import UNUSABLE_FLAGS
from jointcal.io import listed_record, read_run, write_csv_atomic
from jointcal.modal import FLAG_WORDS, modal_properties, scatter


def main(smk) -> None:
    runs = pd.read_csv(smk.input.runs, dtype={"flags": str})
    env_dir = Path(smk.input.env[0]).parent
    records = list(smk.input.records)
    rows, notes = [], []
    for row in runs.to_dict("records"):
        rid = row["run_id"]
        meta = json.loads((env_dir / f"{rid}.json").read_text())
        env = pd.read_csv(env_dir / f"{rid}.csv")
        ingest_flags = [f for f in str(row.get("flags") or "").split(";") if f and f != "nan"]
        if meta.get("error"):
            out = {k: row.get(k) for k in ("run_id", "assembly", "sequence", "direction")}
            out["flags"] = ";".join(ingest_flags + ["unusable"])
            notes.append(f"{rid}: {meta['error']}")
        else:
            path = listed_record(str(row["file"]), records)  # whole relative path: basenames may repeat
            record = read_run(path) if path else None
            out = modal_properties(env, row, rate_hz_per_s=meta["rate_hz_per_s"], record=record, **smk.params.modal)
            out["flags"] = ";".join(dict.fromkeys(ingest_flags + [f for f in out["flags"].split(";") if f]))
            out["window_s"] = meta["window_s"]
        wrong = [f for f in ingest_flags if f.split(":")[0] in UNUSABLE_FLAGS]
        if wrong and "unusable" not in out["flags"].split(";"):  # wrong units, level, channels; clipped: no fit
            out["flags"] = ";".join([*out["flags"].split(";"), "unusable"]).lstrip(";")
            notes.append(f"{rid}: unusable: ingest flagged {', '.join(wrong)} (see the ingest log); "
                         "left out of the calibration")
        for flag in [f for f in out["flags"].split(";") if f.split(":")[0] in FLAG_WORDS or ":" in f]:
            notes.append(f"{rid}: {flag.split(':')[0]}: {FLAG_WORDS.get(flag.split(':')[0], flag)}.")
        rows.append(out)
    table = pd.DataFrame(rows)
    write_csv_atomic(table, smk.output.table)
    write_csv_atomic(scatter(table), smk.output.scatter)
    lines = [f"jointcal: warning: {n}" for n in notes]
    for line in lines:
        print(line, file=sys.stderr)
    lines.append(f"jointcal: modal properties of {len(table)} runs, {sum(table['flags'].fillna('') != '')} flagged")
    Path(smk.log[0]).write_text("\n".join(lines) + "\n")


main(snakemake)  # noqa: F821
