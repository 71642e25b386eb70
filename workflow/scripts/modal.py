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

from jointcal.io import UNUSABLE_FLAGS, listed_record, read_run, write_csv_atomic
from jointcal.measure.envelopes import ENVELOPE_COLUMNS
from jointcal.measure.frf import frf_table
from jointcal.measure.modal import FLAG_WORDS, modal_properties
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
        ingest_flags = [f for f in str(row.get("flags") or "").split(";") if f and f != "nan"]
        path = listed_record(str(row["file"]), records)  # whole relative path: basenames may repeat
        record = read_run(path, row) if path else None
        if meta.get("error") and record is None:
            out = {k: row.get(k) for k in ("run_id", "assembly", "sequence", "direction")}
            out["flags"] = ";".join(ingest_flags + ["unusable"])
            notes.append(f"{rid}: {meta['error']}")
        else:
            if meta.get("error"):  # no envelopes: the whole-record FRF alone
                env = pd.DataFrame(columns=list(ENVELOPE_COLUMNS))
                notes.append(f"{rid}: {meta['error']} (the resonance comes from the whole-record FRF)")
            rate = meta.get("rate_hz_per_s", row["sweep_rate_hz_per_s"])
            out, frf = modal_properties(env, row, rate_hz_per_s=rate, record=record, with_frf=True,
                                        **smk.params.modal)
            out["flags"] = ";".join(dict.fromkeys(ingest_flags + [f for f in out["flags"].split(";") if f]))
            out["window_s"] = meta.get("window_s")
            if len(frf):
                df_line = frf["freq_hz"].iloc[1] - frf["freq_hz"].iloc[0]  # zero-padded spacing, Hz
                pad = max(1, int(round(row["sample_rate_hz"] / len(record) / df_line)))  # keep independent lines
                write_csv_atomic(frf_table(frf.iloc[::pad].reset_index(drop=True), rid), frf_dir / f"{rid}.csv")
        wrong = [f for f in ingest_flags if f.split(":")[0] in UNUSABLE_FLAGS]
        if wrong and "unusable" not in out["flags"].split(";"):  # wrong units, level, channels; clipped: no fit
            out["flags"] = ";".join([*out["flags"].split(";"), "unusable"]).lstrip(";")
            notes.append(f"{rid}: unusable: ingest flagged {', '.join(wrong)} (see the ingest log); "
                         "left out of the calibration")
        for flag in [f for f in out["flags"].split(";") if f.split(":")[0] in FLAG_WORDS or ":" in f]:
            why = f" ({out['sweep_note']})" if flag == "sweep_fit_failed" and out.get("sweep_note") else ""
            notes.append(f"{rid}: {flag.split(':')[0]}: {FLAG_WORDS.get(flag.split(':')[0], flag)}{why}.")
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
