"""Snakemake script of rule ``envelopes_run``: one run's envelopes and their metadata.

A run that cannot be processed (too short, no drive found) gets an empty envelope
table and its one-sentence reason in the metadata, so the other runs go on and the
modal stage flags it. (No ``from __future__``: Snakemake prepends a preamble.)
"""
import sys
from pathlib import Path

import pandas as pd

from jointcal.io import read_run, write_csv_atomic, write_json_atomic
from jointcal.measure.envelopes import ENVELOPE_COLUMNS, envelopes, meta_dict


def main(smk) -> None:
    runs = pd.read_csv(smk.input.runs, dtype={"flags": str}).set_index("run_id", drop=False)
    row = runs.loc[smk.wildcards.run_id].to_dict()
    record = read_run(smk.input.record, row)
    try:
        env, meta = envelopes(record, row, **smk.params.envelopes)
        meta = {**meta_dict(meta), "error": ""}
        note = f"jointcal: {row['run_id']}: {meta['n_frames']} frames, window {meta['window_s'] * 1e3:.1f} ms"
    except ValueError as exc:
        env = pd.DataFrame(columns=list(ENVELOPE_COLUMNS))
        meta = {"error": str(exc)}
        note = f"jointcal: warning: {exc}"
        print(note, file=sys.stderr)
    write_csv_atomic(env, smk.output.env)
    write_json_atomic(meta, smk.output.meta)
    Path(smk.log[0]).write_text(note + "\n")


main(snakemake)  # noqa: F821
