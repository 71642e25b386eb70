"""Snakemake script of rule ``modal_properties``: modal_properties.csv, scatter.csv, frf/.

Every run gets a row; a run with problems gets flags and a one-sentence warning in the
log and on stderr, never a silent drop. Each run's whole-record FRF (H1, band-averaged
H2 and coherence, the fitted displacement ratio; `jointcal.measure.frf`) goes to
``frf/<run_id>.csv``. A run the envelope stage could not process (a chirp too short
for its window) still gets the FRF read-out. (No ``from __future__``: see envelopes.py.)
"""
import json
import sys
from pathlib import Path

import pandas as pd

from jointcal.io import listed_record, read_run, write_csv_atomic
from jointcal.measure.envelopes import ENVELOPE_COLUMNS
from jointcal.measure.flags import run_flags
from jointcal.measure.frf import frf_table
from jointcal.measure.modal import modal_properties
from jointcal.measure.scatter import scatter


def main(smk) -> None:
    runs = pd.read_csv(smk.input.runs, dtype={"flags": str})
    env_dir = Path(smk.input.env[0]).parent
    records = list(smk.input.records)
    frf_dir = Path(smk.output.frf)
    frf_dir.mkdir(parents=True, exist_ok=True)
    rows, notes = [], []
    for row in runs.to_dict("records"):
        rid = row["run_id"]
        meta = json.loads((env_dir / f"{rid}.json").read_text())
        env = pd.read_csv(env_dir / f"{rid}.csv")
        path = listed_record(str(row["file"]), records)  # whole relative path: basenames may repeat
        record = read_run(path, row) if path else None
        if meta.get("error") and record is None:
            out = {k: row.get(k) for k in ("run_id", "assembly", "sequence", "direction")}
            out["flags"] = "unusable"
            notes.append(f"{rid}: {meta['error']}")
        else:
            if meta.get("error"):  # no envelopes: the whole-record FRF alone
                env = pd.DataFrame(columns=list(ENVELOPE_COLUMNS))
                notes.append(f"{rid}: {meta['error']} (the resonance comes from the whole-record FRF)")
            rate = meta.get("rate_hz_per_s", row["sweep_rate_hz_per_s"])
            out, frf = modal_properties(env, row, rate_hz_per_s=rate, record=record, with_frf=True,
                                        **smk.params.modal)
            out["window_s"] = meta.get("window_s")
            if len(frf):
                df_line = frf["freq_hz"].iloc[1] - frf["freq_hz"].iloc[0]  # zero-padded spacing, Hz
                pad = max(1, int(round(row["sample_rate_hz"] / len(record) / df_line)))  # keep independent lines
                write_csv_atomic(frf_table(frf.iloc[::pad].reset_index(drop=True), rid), frf_dir / f"{rid}.csv")
        out["flags"], flag_notes = run_flags(row.get("flags"), out["flags"], rid, sweep_note=out.get("sweep_note"))
        notes += flag_notes
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
