"""Snakemake script of rule ``envelopes_runs``: every run's envelopes and their metadata.

The runs are spread over a process pool of snakemake.threads workers. A run that cannot be
processed (too short, no drive found) gets an empty envelope table and its one-sentence
reason in the metadata and the log, so the other runs go on and the modal stage flags it.
(No ``from __future__``: Snakemake prepends a preamble.)
"""
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal.io import listed_record, read_run, test_kind, write_csv_atomic, write_json_atomic
from jointcal.measure.envelopes import ENVELOPE_COLUMNS, envelopes, meta_dict


def one_run(path: str, row: dict, settings: dict, env_file: str, meta_file: str) -> tuple[str, bool]:
    """Write one run's envelopes and metadata; return its log line and whether it is a warning."""
    env, meta = pd.DataFrame(columns=list(ENVELOPE_COLUMNS)), {"error": "", "test": test_kind(row)}
    note = (f"{row['run_id']}: a {meta['test']} run, no sweep envelopes", False)  # read by modal from its record
    if meta["test"] == "sweep":
        try:
            env, m = envelopes(read_run(path, row), row, **settings)
            meta = {**meta_dict(m), "error": ""}
            note = (f"{row['run_id']}: {meta['n_frames']} frames, window {meta['window_s'] * 1e3:.1f} ms", False)
        except ValueError as exc:
            meta, note = {"error": str(exc)}, (str(exc), True)
    write_csv_atomic(env, env_file)
    write_json_atomic(meta, meta_file)
    return note


with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    table = pd.read_csv(smk.input.runs, dtype={"flags": str}).set_index("run_id", drop=False)
    rows = [table.loc[Path(f).stem].to_dict() for f in smk.output.env]
    paths = [listed_record(str(r["file"]), list(smk.input.records)) for r in rows]  # whole path: basenames may repeat
    for line, warn in job.map(one_run, paths, rows, [dict(smk.params.envelopes)] * len(rows), smk.output.env,
                              smk.output.meta):
        (job.warn if warn else job.log)(line)
