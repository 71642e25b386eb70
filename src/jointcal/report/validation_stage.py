"""The validation's figure on files (rule ``validate_figures``): Fig. 3.11 over every unit, named by
`jointcal._campaign_index.unit_labels`.

One module per report rule, so that each rule's code hash (`jointcal._workflow.stage_hash`) holds the
code it runs and no more.
"""
from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from .._campaign_index import unit_labels
from ..io import write_bytes_atomic
from .validation import validation_figure

__all__ = ["run_validate_figures"]

_Path = str | os.PathLike[str]


def run_validate_figures(metrics_files: Sequence[_Path], summary_files: Sequence[_Path],
                         envelope_dirs: Sequence[_Path], *, figure_png: _Path) -> list[str]:
    """Fig. 3.11 from the validation's tables, one unit per file.

    Parameters
    ----------
    metrics_files, summary_files, envelope_dirs : sequence of paths
        Each unit's ``metrics.csv``, ``summary.json`` and ``envelopes/`` (with its ``traces/``), in one order.
    figure_png : path
        Where the figure goes.

    Returns
    -------
    list of str
        One line per unit for the log: its envelope error E.
    """
    names = unit_labels(summary_files)  # assembly (and mode: jointcal._campaign_index)
    metrics = {a: pd.read_csv(p) for a, p in zip(names, metrics_files)}
    errors = {a: json.loads(Path(p).read_text())["E"] for a, p in zip(names, summary_files)}
    frames = {a: {p.stem: pd.read_csv(p) for p in sorted(Path(d).glob("*.csv"))}
              for a, d in zip(names, envelope_dirs)}
    traces = {a: {p.stem: pd.read_csv(p) for p in sorted((Path(d) / "traces").glob("*.csv"))}
              for a, d in zip(names, envelope_dirs)}
    write_bytes_atomic(validation_figure(frames, metrics, errors, traces=traces), figure_png)
    return [f"{a}: E = {e:.2f}" for a, e in errors.items()]
