"""The posterior's figures and tables on files: one unit's corner plot and its caption (rule
``posterior_corner``), and Fig. 3.8, Table 3.2 and QSMA versus harmonic balance over every unit (rule
``posterior_report``, its units named by `jointcal._campaign_index.unit_labels`).

One module per report rule (these two share theirs), so that each rule's code hash
(`jointcal._workflow.stage_hash`) holds the code it runs and no more.
"""
from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._campaign_index import unit_labels, unit_of
from ..calibrate import PARAMS, CalibrateSettings, read_modal
from ..io import write_bytes_atomic, write_csv_atomic
from ..posterior import PosteriorSettings
from ._corner_axes import corner_coordinates
from .calibration import amplitude_figure
from .corner import corner_figure
from .summary import chain_status, ga_best_point, rst_escape
from .tables import qsma_at_measured, table_3_2, table_3_2_markdown

__all__ = ["run_posterior_corner", "run_posterior_report"]

_Path = str | os.PathLike[str]


def run_posterior_corner(chain_npz: _Path, constraints_txt: _Path, best_json: _Path, history_csv: _Path,
                         assembly: str, *, calibrate: Mapping[str, Any], posterior: Mapping[str, Any],
                         corner_png: _Path, caption_rst: _Path) -> str:
    """One unit's corner plot, stamped with its convergence, the GA best, the polished optimum, the prior
    bounds and its modes; and the run-generated part of its caption.

    Axes: log10 of the scale parameters and noise scales, chi linear (`jointcal.report._corner_axes`).

    Parameters
    ----------
    chain_npz, constraints_txt : path
        The posterior's ``chain.npz`` and ``constraints.txt``.
    best_json, history_csv : path
        The calibration's ``ga_best.json`` and ``ga_history.csv``.
    assembly : str
        Named in the title.
    calibrate, posterior : mapping
        The config's sections (the bounds drawn; ``tau_factor``).
    corner_png, caption_rst : path
        Where the figure and the caption go.

    Returns
    -------
    str
        The line for the log: the draws and the chain's convergence.
    """
    best = json.loads(Path(best_json).read_text())
    cal = CalibrateSettings.from_config(calibrate).resolved(best)
    with np.load(chain_npz) as z:
        arrays = {k: z[k] for k in z.files}
    samples, names = arrays["samples"], [str(n) for n in arrays["sample_names"]]
    points = {"GA best": ga_best_point(pd.read_csv(history_csv)),
              "polished optimum": {p: best[p] for p in PARAMS}}
    x, labels, points, bounds = corner_coordinates(samples, names, points, cal.full_bounds)
    ok, line = chain_status(arrays, tau_factor=PosteriorSettings.from_config(posterior).tau_factor)
    write_bytes_atomic(corner_figure(x, labels, title=f"posterior of {assembly}", points=points,
                                     bounds=bounds, modes=arrays.get("sample_mode"), stamp=(line.split(";")[0], ok)),
                       corner_png)
    text = [f"**This run: {rst_escape(line)}.**"]
    text += [rst_escape(s) for s in Path(constraints_txt).read_text().splitlines()[1:] if s.strip()]
    write_bytes_atomic(("\n\n".join(text) + "\n").encode(), caption_rst)
    return f"corner plot of {len(samples)} posterior draws; {line}"


def run_posterior_report(inputs: Mapping[str, Sequence[_Path]], calibrate: Mapping[str, Any], *, figure_png: _Path,
                         table_csv: _Path, markdown_md: _Path, qsma_csv: _Path) -> list[str]:
    """Fig. 3.8, Table 3.2 (csv and markdown) and QSMA versus harmonic balance at the measured amplitudes.

    Parameters
    ----------
    inputs : mapping
        One file per unit, in one order, by the names of rule ``posterior_report``'s inputs: ``modal`` (the
        unit's modal_properties.csv), ``best`` (ga_best.json), ``curves`` (model_curves.csv), ``summary``,
        ``predictive`` and ``identified`` (the posterior's csv files).
    calibrate : mapping
        The config's ``calibrate`` section.
    figure_png, table_csv, markdown_md, qsma_csv : path
        Where Fig. 3.8, Table 3.2 (csv, markdown) and the QSMA comparison go.

    Returns
    -------
    list of str
        One line per assembly for the log: how far QSMA's frequency lies above harmonic balance's.
    """
    cal = CalibrateSettings.from_config(calibrate)
    names = unit_labels(inputs["best"])  # assembly (and mode: jointcal._campaign_index)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, inputs["best"])}
    measured, comparison = {}, []
    for a, unit_modal in zip(names, inputs["modal"]):
        d = read_modal(unit_modal, unit_of(unit_modal)[0], damping=cal.damping)
        measured[a] = pd.DataFrame({"q_in": d.q, "f_hz": d.f, "zeta": d.zeta})
        comparison.append(qsma_at_measured(best[a], d, a, m=cal.resolved(best[a]).m, viscous=cal.viscous))
    curves, bands, summaries, identified = ({a: pd.read_csv(p) for a, p in zip(names, files)} for files in (
        inputs["curves"], inputs["predictive"], inputs["summary"], inputs["identified"]))
    write_bytes_atomic(amplitude_figure(measured, curves, bands, model=cal.model), figure_png)
    table = table_3_2(best, summaries, identified)
    write_csv_atomic(table, table_csv)
    write_bytes_atomic(table_3_2_markdown(table).encode(), markdown_md)
    qvh = pd.concat(comparison, ignore_index=True)
    write_csv_atomic(qvh, qsma_csv)
    return [f"{a}: QSMA frequency above harmonic balance by {g['df_percent'].min():.3f}% to "
            f"{g['df_percent'].max():.3f}% at the measured amplitudes" for a, g in qvh.groupby("assembly", sort=False)]
