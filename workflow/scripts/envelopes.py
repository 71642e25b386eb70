"""Snakemake script of rule ``envelopes_runs``: every run's envelopes and their metadata.

The runs are spread over a process pool of snakemake.threads workers. A run that cannot be
processed (too short, no drive found) gets an empty envelope table and its one-sentence
reason in the metadata, so the other runs go on and the modal stage flags it.
(No ``from __future__``: Snakemake prepends a preamble.)
"""
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd

from jointcal.io import listed_record, read_run, test_kind, write_csv_atomic, write_json_atomic
from jointcal.measure.envelopes import ENVELOPE_COLUMNS, envelopes, meta_dict


def one_run(path: str, row: dict, settings: dict, env_file: str, meta_file: str) -> str:
    """Write one run's envelopes and metadata; return its log line."""
    if test_kind(row) != "sweep":  # a dwell or ring-down: read by the modal stage from its record
        write_csv_atomic(pd.DataFrame(columns=list(ENVELOPE_COLUMNS)), env_file)
        write_json_atomic({"error": "", "test": test_kind(row)}, meta_file)
        return f"jointcal: {row['run_id']}: a {test_kind(row)} run, no sweep envelopes"
    try:
        env, meta = envelopes(read_run(path, row), row, **settings)
        meta = {**meta_dict(meta), "error": ""}
        note = f"jointcal: {row['run_id']}: {meta['n_frames']} frames, window {meta['window_s'] * 1e3:.1f} ms"
    except ValueError as exc:
        env, meta = pd.DataFrame(columns=list(ENVELOPE_COLUMNS)), {"error": str(exc)}
        note = f"jointcal: warning: {exc}"
    write_csv_atomic(env, env_file)
    write_json_atomic(meta, meta_file)
    return note


def main(smk) -> None:
    rows = pd.read_csv(smk.input.runs, dtype={"flags": str}).set_index("run_id", drop=False)
    jobs = []
    for env_file, meta_file in zip(smk.output.env, smk.output.meta):
        row = rows.loc[Path(env_file).stem].to_dict()
        path = listed_record(str(row["file"]), list(smk.input.records))  # whole path: basenames may repeat
        jobs.append((path, row, dict(smk.params.envelopes), env_file, meta_file))
    n = max(1, min(int(smk.threads), len(jobs)))
    if n > 1:
        with ProcessPoolExecutor(max_workers=n) as ex:
            notes = list(ex.map(one_run, *zip(*jobs)))
    else:
        notes = [one_run(*job) for job in jobs]
    for note in notes:
        if "warning" in note:
            print(note, file=sys.stderr)
    Path(smk.log[0]).write_text("\n".join(notes) + "\n")


main(snakemake)  # noqa: F821
