"""The envelope stage on files: every run's envelopes and their metadata, written.

Outputs (written atomically): ``<run_id>.csv`` (`jointcal.measure.envelopes.envelopes`'s table, empty for a
run that is not a sweep or cannot be processed) and ``<run_id>.json`` (its metadata, with ``error``: the
one-sentence reason a sweep could not be processed, so the other runs go on and the modal stage flags it).
Kept apart from `jointcal.measure.stage` (the modal stage), so that this stage's code hash
(`jointcal._workflow.stage_hash`) holds the envelope code alone.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from ..io import listed_record, read_run, run_test_kind, write_csv_atomic, write_json_atomic
from .envelopes import ENVELOPE_COLUMNS, envelopes, meta_dict

__all__ = ["run_envelopes"]

_Path = str | os.PathLike[str]


def _one_run(path: str, row: dict, settings: dict, env_file: str, meta_file: str) -> tuple[str, bool]:
    """Write one run's envelopes and metadata; return its log line and whether it is a warning."""
    test = run_test_kind(row)
    env, meta = pd.DataFrame(columns=list(ENVELOPE_COLUMNS)), {"error": "", "test": test.name}
    note = (f"{row['run_id']}: a {test.name} run, no sweep envelopes", False)  # read by modal from its record
    if test.swept:
        try:
            env, m = envelopes(read_run(path, row), row, **settings)
            meta = {**meta_dict(m), "error": ""}
            note = (f"{row['run_id']}: {meta['n_frames']} frames, window {meta['window_s'] * 1e3:.1f} ms", False)
        except ValueError as exc:
            meta, note = {"error": str(exc)}, (str(exc), True)
    write_csv_atomic(env, env_file)
    write_json_atomic(meta, meta_file)
    return note


def run_envelopes(runs_csv: _Path, record_files: Sequence[_Path], settings: Mapping[str, Any],
                  env_files: Sequence[_Path], meta_files: Sequence[_Path], *,
                  mapper: Callable[..., Iterable[tuple[str, bool]]] = map,
                  log: Callable[[str], None] = lambda line: None,
                  warn: Callable[[str], None] = lambda line: None) -> None:
    """Write the envelopes and metadata of the runs named by `env_files`.

    Parameters
    ----------
    runs_csv : path
        The ingest table (``runs.csv``).
    record_files : sequence of paths
        The campaign's record files, as listed by the workflow (a run's file is found by its whole
        relative path: basenames may repeat).
    settings : mapping
        The ``envelopes`` section of the config (keywords of `jointcal.measure.envelopes.envelopes`).
    env_files, meta_files : sequence of paths
        ``<run_id>.csv`` and ``<run_id>.json`` to write, one of each per run (the run id is the file's stem).
    mapper : callable, optional
        ``mapper(fn, *iterables)``: the builtin `map`, or one over a process pool (`jointcal._stage_job.Job.map`).
    log, warn : callable, optional
        Receive each run's line: its frames and window, or the reason it could not be processed.
    """
    table = pd.read_csv(runs_csv, dtype={"flags": str}).set_index("run_id", drop=False)
    rows = [table.loc[Path(f).stem].to_dict() for f in env_files]
    records = [str(r) for r in record_files]
    paths = [listed_record(str(r["file"]), records) for r in rows]  # whole path: basenames may repeat
    for line, is_warning in mapper(_one_run, paths, rows, [dict(settings)] * len(rows), list(env_files),
                                list(meta_files)):
        (warn if is_warning else log)(line)
