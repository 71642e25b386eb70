"""Snakemake script of rule ``modal_properties``: modal_properties.csv, scatter.csv, frf/.

Every run gets a row per mode its band holds (`jointcal.measure.campaign`); a run with problems
gets flags and a one-sentence warning in the log and on stderr, never a silent drop. Each run's
whole-record FRF (H1, band-averaged H2 and coherence, the fitted displacement ratio per mode;
`jointcal.measure.frf`) goes to ``frf/<run_id>.csv``. Every run's amplitude-dependent points, from
every test kind, go to ``backbone.csv`` (`jointcal.measure.testkinds`). (No ``from __future__``: see envelopes.py.)
"""
import json
import sys
from pathlib import Path

import pandas as pd

from jointcal.io import listed_record, read_run, write_csv_atomic
from jointcal.measure.campaign import campaign_modal
from jointcal.measure.flags import run_flags
from jointcal.measure.frf import frf_table
from jointcal.measure.scatter import scatter
from jointcal.measure.testkinds import backbone_table


def main(smk) -> None:
    runs = pd.read_csv(smk.input.runs, dtype={"flags": str})
    env_dir = Path(smk.input.env[0]).parent
    records = list(smk.input.records)
    frf_dir = Path(smk.output.frf)
    frf_dir.mkdir(parents=True, exist_ok=True)

    def load(row):
        rid = row["run_id"]
        path = listed_record(str(row["file"]), records)  # whole relative path: basenames may repeat
        return (pd.read_csv(env_dir / f"{rid}.csv"), json.loads((env_dir / f"{rid}.json").read_text()),
                read_run(path, row) if path else None)

    points = []
    rows, frf, notes = campaign_modal(runs, load, smk.params.modal, points=points)
    ingest_flags = dict(zip(runs["run_id"], runs["flags"]))
    for out in rows:
        out["flags"], flag_notes = run_flags(ingest_flags.get(out["run_id"]), out["flags"], out["run_id"],
                                             sweep_note=out.get("sweep_note"))
        notes += flag_notes
    for rid, tab in frf.items():
        write_csv_atomic(frf_table(tab, rid), frf_dir / f"{rid}.csv")
    table = pd.DataFrame(rows)
    table.insert(2, "mode", table.pop("mode"))
    write_csv_atomic(table, smk.output.table)
    write_csv_atomic(scatter(table), smk.output.scatter)
    write_csv_atomic(backbone_table(table, points), smk.output.backbone)
    lines = [f"jointcal: warning: {n}" for n in notes]
    for line in lines:
        print(line, file=sys.stderr)
    lines.append(f"jointcal: modal properties of {table['run_id'].nunique()} runs at {table['mode'].nunique()} "
                 f"modes, {sum(table['flags'].fillna('') != '')} rows flagged")
    Path(smk.log[0]).write_text("\n".join(lines) + "\n")


main(snakemake)  # noqa: F821
