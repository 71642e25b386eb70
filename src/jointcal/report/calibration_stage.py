"""The calibration's figures on files (rule ``calibration_figures``): the GA's exploration matrix (Figs.
3.9/3.10), its convergence and the run-generated part of their caption.

One module per report rule, so that each rule's code hash (`jointcal._workflow.stage_hash`) holds the
code it runs and no more.
"""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from ..calibrate import PARAMS, CalibrateSettings
from ..io import write_bytes_atomic
from .calibration import convergence_figure, exploration_caption, exploration_figure
from .summary import ga_best_point

__all__ = ["run_calibration_figures"]

_Path = str | os.PathLike[str]


def run_calibration_figures(history_csv: _Path, logbook_csv: _Path, best_json: _Path, name: str,
                            calibrate: Mapping[str, Any], *, exploration_png: _Path, convergence_png: _Path,
                            caption_rst: _Path) -> str:
    """The GA's exploration matrix (Figs. 3.9/3.10), its convergence and the run-generated part of their caption.

    Parameters
    ----------
    history_csv, logbook_csv, best_json : path
        The calibration's ``ga_history.csv``, ``ga_logbook.csv`` and ``ga_best.json``.
    name : str
        The assembly, the figures' title.
    calibrate : mapping
        The config's ``calibrate`` section (the bounds drawn).
    exploration_png, convergence_png, caption_rst : path
        Where the two figures and the caption go.

    Returns
    -------
    str
        The line for the log.
    """
    history = pd.read_csv(history_csv)
    best = json.loads(Path(best_json).read_text())
    bounds = CalibrateSettings.from_config(calibrate).resolved(best).full_bounds
    ga = ga_best_point(history)
    polished = {p: best[p] for p in PARAMS} | {"objective": best["objective"]}
    write_bytes_atomic(exploration_figure(history, title=name, ga_best=ga, polished=polished, bounds=bounds),
                       exploration_png)
    write_bytes_atomic(convergence_figure({name: pd.read_csv(logbook_csv)}), convergence_png)
    write_bytes_atomic(exploration_caption(history, best, ga, polished, bounds).encode(), caption_rst)
    return f"GA figures of {name!r} from {len(history)} evaluations"
