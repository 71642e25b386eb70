"""The report's opening summary and the run-generated parts of its captions.

Pure functions from the stages' outputs to text and HTML:

* `ga_best_point` -- the GA's own best individual (the polish may move far from it);
* `bound_hits` -- parameters at a search bound;
* `chain_status` -- one line per posterior: steps in units of tau, converged or why not;
* `table_3_2_html` -- Table 3.2 in the paper's layout: the posterior (parameters the data
  leave to the bounds marked, no value given), then the GA's points as members of it;
* `summary_html` -- the verdict (`jointcal.report.verdict`), what the data identify,
  Table 3.2, then the campaign, the flags counted, the convergence and the fit, as one page;
* `landing_html` -- the verdict and the details in a few lines for the landing page.
"""
from __future__ import annotations

import html
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..calibrate.space import LOG_SCALED, PARAMS, UNITS
from ..io import level_column

__all__ = ["rst_escape", "ga_best_point", "bound_hits", "chain_status", "table_3_2_html", "summary_html", "landing_html",
           "fmt"]


def rst_escape(text: str) -> str:
    """Text safe to include in a reStructuredText caption (no inline markup, substitutions or references)."""
    for ch in ("\\", "*", "`", "|", "_", "[", "]"):
        text = text.replace(ch, "\\" + ch)
    return text


def fmt(v: float) -> str:
    """A number in 3-4 significant digits (exponent form outside 1e-3..1e4)."""
    if v is None or not np.isfinite(v):
        return "-"
    if v == 0 or 1e-3 <= abs(v) < 1e4:
        return f"{v:.4g}" if abs(v) >= 1 else f"{v:.3g}"
    mant, exp = f"{v:.3e}".split("e")
    return f"{float(mant):.3g}e{int(exp)}"


def ga_best_point(history: pd.DataFrame) -> dict[str, float]:
    """The GA's best evaluated individual (``ga_history.csv``: objective and the six parameters)."""
    row = history.loc[history["objective"].idxmin()]
    return {p: float(row[p]) for p in PARAMS} | {"objective": float(row["objective"])}


def bound_hits(theta: Mapping[str, float], bounds: Mapping[str, Sequence[float]], tol: float = 1e-3) -> dict[str, str]:
    """Parameters within `tol` of a bound (in decades for log-scaled ones, as a fraction of the range for chi).

    Returns
    -------
    dict
        param -> "lower" or "upper".
    """
    hits = {}
    for p in PARAMS:
        lo, hi = (float(b) for b in bounds[p])
        v = float(theta[p])
        if LOG_SCALED.get(p, True):
            d_lo, d_hi = np.log10(v / lo), np.log10(hi / v)
        else:
            d_lo, d_hi = (v - lo) / (hi - lo), (hi - v) / (hi - lo)
        if d_lo <= tol:
            hits[p] = "lower"
        elif d_hi <= tol:
            hits[p] = "upper"
    return hits


def _touches(p: str, q05: float, q95: float, bounds: Mapping[str, Sequence[float]], tol: float = 0.02) -> str | None:
    """"lower"/"upper" when a 90% interval reaches within `tol` of the prior width of a bound, else None."""
    lo, hi = (float(b) for b in bounds[p])
    f = np.log10 if LOG_SCALED.get(p, True) else (lambda v: v)
    w = f(hi) - f(lo)
    if np.isfinite(q05) and f(q05) - f(lo) <= tol * w:
        return "lower"
    if np.isfinite(q95) and f(hi) - f(q95) <= tol * w:
        return "upper"
    return None


def chain_status(z: Mapping, *, tau_factor: float = 50.0) -> tuple[bool, str]:
    """Convergence of one posterior from its ``chain.npz`` arrays.

    Returns
    -------
    converged : bool
    line : str
        E.g. "converged: 14000 steps = 52 tau" or "NOT converged: 6.2 tau (stopped early: ...)".
    """
    hist = np.asarray(z["tau_history"], dtype=float)
    n, tau = hist[-1, 0], float(np.max(hist[-1, 1:]))
    multiple = n / tau
    converged = bool(z["converged"])
    reason = str(z["stop_reason"]) if "stop_reason" in z else ("converged" if converged else "max_steps")
    if converged:
        return True, f"converged: {n:.0f} steps = {multiple:.1f} tau (tau {tau:.0f} steps)"
    why = {"max_steps": "stopped at the step cap",
           "projected": (f"stopped early: {tau_factor:g} tau projected to need "
                         + (f"{float(z['projected_steps']):.0f} steps" if np.isfinite(float(z.get(
                             "projected_steps", np.inf))) else "more steps than any cap (tau grows with the chain)"))}
    return False, (f"NOT converged: {multiple:.1f} tau of the {tau_factor:g} required ({n:.0f} steps, tau {tau:.0f}); "
                   f"{why.get(reason, reason)}")


_CSS = """<style>
body{font-family:sans-serif;margin:1em}
.jc-summary{font-size:14px;line-height:1.4;max-width:1250px}
.jc-summary table{border-collapse:collapse;margin:0.4em 0 1em 0;font-size:13px;max-width:1250px}
.jc-summary th,.jc-summary td{border:1px solid #bbb;padding:2px 6px;text-align:right;white-space:normal;
  vertical-align:top}
.jc-summary table.t32 td{min-width:7em}
.jc-summary table.ident td.lab{max-width:38em}
.jc-summary ol.verdict li{margin-bottom:0.4em}
.jc-summary th{background:#eee}
.jc-summary td.lab{text-align:left}
.jc-summary td.bound{background:#fde2c4}
.jc-summary td.free{color:#777;font-style:italic}
.jc-summary .bad{color:#b00000;font-weight:bold}
.jc-summary .good{color:#006400;font-weight:bold}
</style>"""


def _cell(text: str, cls: str = "") -> str:
    return f'<td class="{cls}">{text}</td>' if cls else f"<td>{text}</td>"


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
        cells = []
        for p in PARAMS:
            r = g.loc[p]
            if free[p]:
                cells.append(_cell(f"<i>not identified</i><br><small>spans {fmt(lo[p])} to {fmt(hi[p])} (bounds)</small>",
                                   "free"))
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


def summary_html(*, campaign: str, runs: pd.DataFrame, modal: pd.DataFrame, status: Mapping[str, tuple[bool, str]],
                 constraints: Mapping[str, str], table_html: str, fits: Mapping[str, str] | None = None,
                 verdict: str = "", identified: str = "") -> str:
    """The report's opening summary as an HTML fragment: the verdict, what the data identify, Table 3.2,
    then the details (campaign, run flags, convergence, the constraint sentences).

    Parameters
    ----------
    campaign : str
        The campaign folder.
    runs : DataFrame
        ``runs.csv`` of the ingest stage (run_id, assembly, flags, ...).
    modal : DataFrame
        ``modal_properties.csv`` (run_id, assembly, flags).
    status : mapping assembly -> (converged, line)
        `chain_status` of each posterior.
    constraints : mapping assembly -> str
        ``constraints.txt`` of each posterior (its sentences are listed).
    table_html : str
        `table_3_2_html`.
    fits : mapping assembly -> str, optional
        Extra sentences per assembly.
    verdict : str
        `jointcal.report.verdict.verdict_html`: opens the page.
    identified : str
        `jointcal.report.verdict.identified_html` of each assembly, after the verdict.
    """
    out = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>jointcal summary</title>", _CSS,
           "</head><body>", '<div class="jc-summary">', "<h2>jointcal: summary of this run</h2>", verdict, identified,
           "<p><b>Table 3.2</b> (the paper's calibrated parameters, in its layout)</p>", table_html,
           "<h3>Details</h3>"]
    n_asm = runs["assembly"].nunique() if "assembly" in runs else 0
    level = level_column(runs.columns)
    levels = "" if level is None else ", levels " + ", ".join(f"{v:g}" for v in sorted(runs[level].dropna().unique()))
    out.append(f"<p><b>Campaign</b> <code>{html.escape(campaign)}</code>: {len(runs)} runs on {n_asm} assemblies"
               f"{html.escape(levels)}{' ' + level.split('_', 1)[1] if level else ''}.</p>")
    flag_rows = []
    for label, t in (("ingest (runs.csv)", runs), ("modal (modal_properties.csv)", modal)):
        n, detail = _flag_counts(t)
        flag_rows.append(f"<li>{label}: <b>{n}</b> of {len(t)} runs flagged"
                         + (f" ({html.escape(detail)})" if detail else "") + "</li>")
    out.append("<p><b>Run flags</b></p><ul>" + "".join(flag_rows) + "</ul>")
    out.append("<p><b>Posterior convergence</b></p><ul>")
    for name, (ok, line) in status.items():
        cls = "good" if ok else "bad"
        out.append(f"<li>{html.escape(name)}: <span class='{cls}'>{html.escape(line)}</span></li>")
    out.append("</ul>")
    for name, text in constraints.items():
        out.append(f"<p><b>The posterior of {html.escape(name)}</b></p><ul>")
        out.extend(f"<li>{html.escape(s)}</li>" for s in text.strip().splitlines() if s.strip())
        if fits and name in fits:
            out.append(f"<li>{html.escape(fits[name])}</li>")
        out.append("</ul>")
    out.append("</div></body></html>")
    return "\n".join(out) + "\n"


def _flag_counts(t: pd.DataFrame) -> tuple[int, str]:
    f = t["flags"].fillna("").astype(str) if "flags" in t else pd.Series([], dtype=str)
    flagged = f[f.str.strip() != ""]
    kinds: dict[str, int] = {}
    for v in flagged:
        for k in v.replace(",", ";").split(";"):
            k = k.strip().split(":")[0].split("(")[0].strip()
            if k:
                kinds[k] = kinds.get(k, 0) + 1
    return len(flagged), "; ".join(f"{k}: {n}" for k, n in sorted(kinds.items()))


def landing_html(*, runs: pd.DataFrame, modal: pd.DataFrame, status: Mapping[str, tuple[bool, str]],
                 notes: Mapping[str, Sequence[str]] | None = None, verdict: str = "") -> str:
    """The report's landing text: the verdict of the run (``verdict``,
    `jointcal.report.verdict.landing_verdict`), then run flags counted and each posterior's convergence.

    Short on purpose: Snakemake's landing page centres its content and clips a long one.
    ``notes`` adds short warnings per assembly (e.g. multimodal, a parameter at a bound).
    """
    out = [verdict, '<div style="font-size:12px;line-height:1.3;color:#444;text-align:left">'
           "<div><b>Details</b></div>"]
    for label, t in (("ingest", runs), ("modal", modal)):
        n, detail = _flag_counts(t)
        out.append(f"<div>Run flags, {label}: <b>{n}</b> of {len(t)} runs"
                   + (f" ({html.escape(detail)})" if detail else "") + "</div>")
    for name, (ok, line) in status.items():
        colour = "#006400" if ok else "#8a4b00"
        extra = "".join(f"; {html.escape(n)}" for n in (notes or {}).get(name, ()))
        out.append(f"<div>Posterior chain <b>{html.escape(name)}</b>: <span style='color:{colour}'>"
                   f"{html.escape(line)}</span>{extra}</div>")
    out.append("</div>")
    return "\n".join(out) + "\n"
