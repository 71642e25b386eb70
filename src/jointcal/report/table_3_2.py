"""Table 3.2 in the paper's layout, as HTML: the posterior (parameters the data leave to the
bounds marked, no value given), then the GA's points as members of the posterior's set."""
from __future__ import annotations

import html
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..calibrate.space import PARAMS, UNITS
from .summary import _cell, _touches, fmt

__all__ = ["table_3_2_html"]


def _identified_params(identified: pd.DataFrame | None) -> dict[str, bool] | None:
    """param -> identified, from an identified.csv table (None when not given)."""
    if identified is None:
        return None
    t = identified.set_index("quantity")
    return {p: bool(t.loc[p, "identified"]) for p in PARAMS if p in t.index}


def _member(v: float, lo: float, hi: float) -> str:
    """A point of the GA shown as a member of the posterior: its value where the 90% interval holds it."""
    if np.isfinite(lo) and np.isfinite(hi) and not lo <= v <= hi:
        return "<span class='bad'>outside the 90% interval</span>"
    return fmt(v)


def table_3_2_html(table: pd.DataFrame, ga_points: Mapping[str, Mapping[str, float]],
                   modes: Mapping[str, pd.DataFrame] | None = None,
                   bounds: Mapping[str, Sequence[float]] | Mapping[str, Mapping[str, Sequence[float]]] | None = None,
                   model_notes: Mapping[str, str] | None = None,
                   identified: Mapping[str, pd.DataFrame] | None = None) -> str:
    """Table 3.2 in the paper's layout: per assembly the posterior, then the GA's points as members of it.

    Parameters
    ----------
    table : DataFrame
        `jointcal.report.tables.table_3_2` (its ga_optimum column is the polished optimum).
    ga_points : mapping assembly -> dict
        `ga_best_point` of each assembly.
    modes : mapping assembly -> DataFrame, optional
        `jointcal.posterior.find_modes` tables; with two or more modes each gets a row.
    bounds : mapping param -> (lo, hi), or assembly -> param -> (lo, hi), optional
        Search bounds (one set, or each assembly's: a modal model's come from its data):
        intervals that reach a bound are marked.
    model_notes : mapping assembly -> str, optional
        What the parameters mean for each assembly's model (`jointcal.calibrate.model_words`),
        printed under the table where it is not the paper's Ministack.
    identified : mapping assembly -> DataFrame, optional
        identified.csv of each assembly (`jointcal.posterior.identified`). A parameter the data
        leave to the bounds gets no value in any row: "not identified" and the range the bounds
        leave it. Without it the posterior's width ratio decides (the older, bound-dependent rule).
    """
    head = "".join(f"<th>{p} ({html.escape(UNITS[p])})</th>" for p in PARAMS)
    rows = [f"<table class='t32'><tr><th>assembly</th><th>estimate</th>{head}</tr>"]
    all_bounds = bounds
    for name, g in table.groupby("assembly", sort=False):
        bounds = (all_bounds.get(name) if all_bounds and isinstance(all_bounds.get(name), Mapping)
                  else all_bounds)
        g = g.set_index("param")
        ident = _identified_params(identified.get(name) if identified else None)
        free = {p: (not ident[p]) if ident is not None and p in ident
                else (g.loc[p, "constrained"] is False or g.loc[p, "constrained"] == False)  # noqa: E712
                for p in PARAMS}
        lo = {p: float(g.loc[p, "posterior_q05"]) for p in PARAMS}
        hi = {p: float(g.loc[p, "posterior_q95"]) for p in PARAMS}
        t = identified.get(name) if identified else None
        why = {} if t is None or "why_not" not in t else dict(zip(t["quantity"], t["why_not"].fillna("").astype(str)))
        cells = []
        for p in PARAMS:
            r = g.loc[p]
            if free[p]:
                cause = "chain not settled" if why.get(p) else "bounds"  # jointcal.posterior.identified.unsettled
                cells.append(_cell(f"<i>not identified</i><br><small>spans {fmt(lo[p])} to {fmt(hi[p])} ({cause})"
                                   "</small>", "free"))
                continue
            edge = _touches(p, lo[p], hi[p], bounds) if bounds else None
            note = f"<br><small>(touches {edge} bound)</small>" if edge else ""
            cells.append(_cell(f"{fmt(r['posterior_median'])}<br><small>[{fmt(lo[p])}, {fmt(hi[p])}]</small>{note}",
                               "bound" if edge else ""))
        m = None if modes is None else modes.get(name)
        n_modes = 0 if m is None or m.empty else int(m["mode"].max()) + 1
        label = "posterior median<br>[90% interval]" + (" <span class='bad'>(between modes)</span>" if n_modes > 1 else "")
        rows.append(f"<tr><td class='lab'>{html.escape(name)}</td><td class='lab'>{label}</td>{''.join(cells)}</tr>")
        for k in range(n_modes if n_modes > 1 else 0):
            mk = m[m["mode"] == k].set_index("param")
            cells = [_cell("-" if free[p] else f"{fmt(mk.loc[p, 'median'])}<br><small>[{fmt(mk.loc[p, 'q05'])}, "
                           f"{fmt(mk.loc[p, 'q95'])}]</small>") for p in PARAMS]
            w = 100 * float(mk["weight"].iloc[0])
            rows.append(f"<tr><td class='lab'>{html.escape(name)}</td><td class='lab'>mode {k + 1} ({w:.0f}% of the "
                        f"draws)</td>{''.join(cells)}</tr>")
        polished = {p: float(g.loc[p, "ga_optimum"]) for p in PARAMS}
        for label, point in (("polished optimum<br><small>(one member of the posterior's set)</small>", polished),
                             ("GA best before polish<br><small>(one member)</small>", ga_points[name])):
            cells = [_cell("-" if free[p] else _member(float(point[p]), lo[p], hi[p])) for p in PARAMS]
            rows.append(f"<tr><td class='lab'>{html.escape(name)}</td><td class='lab'>{label}</td>{''.join(cells)}</tr>")
    rows.append("</table>")
    for name, words in (model_notes or {}).items():
        if not words.startswith("The paper's Ministack"):
            rows.append(f"<p><b>{html.escape(name)}</b>: {html.escape(words)}</p>")
    rows.append("<p><i>Not identified</i>: the data leave the parameter to the bounds (most of its posterior variance "
                "lies along directions the measurements do not constrain), so no value of it is given; the range is "
                "what the bounds and the identified combinations leave. Orange: a 90% interval that reaches a search "
                "bound. The polished optimum (<code>ga_best.json</code>, where the chain starts) and the GA's own best "
                "are single members of the posterior's set: their identified values are shown where the posterior's "
                "90% interval holds them, and any value of the other parameters in their range fits the data as "
                "well.</p>")
    return "\n".join(rows)
