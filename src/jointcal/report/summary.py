"""The report's opening summary and the run-generated parts of its captions.

Pure functions from the stages' outputs to text and HTML:

* `ga_best_point` -- the GA's own best individual (the polish may move far from it);
* `bound_hits` -- parameters at a search bound;
* `chain_status` -- one line per posterior: steps in units of tau, converged or why not;
* Table 3.2 in the paper's layout: `jointcal.report.table_3_2`;
* `summary_html` -- the verdict (`jointcal.report.verdict`), what the data identify,
  Table 3.2, then the campaign, the flags counted, the convergence and the fit, as one page;
* `landing_html` -- the verdict and the details in a few lines for the landing page.
"""
from __future__ import annotations

import html
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from ..calibrate.space import LOG_SCALED, PARAMS
from ..io import level_column

__all__ = ["rst_escape", "ga_best_point", "bound_hits", "chain_status", "summary_html", "landing_html",
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


def p_value(p: float) -> str:
    """A chi-square test's p: two significant digits from 1e-3 up, where it is read against the rejection level
    (`jointcal.posterior.stage.P_REJECT`; 0.046 must not print as 0.05, nor 0.13 as 0.1), one below."""
    return f"{p:.2g}" if p >= 1e-3 else f"{p:.1g}"


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
    out.append(modes_html(modal))
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


def modes_html(modal: pd.DataFrame) -> str:
    """Which modes each assembly's runs hold, and which are calibrated, as an HTML paragraph.

    Parameters
    ----------
    modal : DataFrame
        ``modal_properties.csv`` (one row per run and mode; `jointcal.measure.modes.with_modes` names the mode
        of a table without the column).

    Returns
    -------
    str
        One list item per (assembly, mode): its frequency range, the runs read at it, and whether it is
        calibrated (read in usable runs at two levels or more: `jointcal.measure.modes.units`) or why not.
    """
    from ..measure.modes import units, with_modes

    if not len(modal) or "assembly" not in modal:
        return ""
    t = with_modes(modal)
    calibrated = set(units(t))
    items = []
    for (asm, mode), g in t[t["mode"] != ""].groupby(["assembly", "mode"], sort=False):
        f = pd.to_numeric(g.get("f_res_hz"), errors="coerce").dropna()
        span = f" ({f.min():.4g}-{f.max():.4g} Hz)" if len(f) else ""
        runs_of = ", ".join(map(str, g["run_id"]))
        why = ("calibrated" if (str(asm), str(mode)) in calibrated
               else "not calibrated: read in usable runs at fewer than two levels")
        items.append(f"<li>{html.escape(f'{asm} {mode}')}{html.escape(span)}: {len(g)} runs ({html.escape(runs_of)}); "
                     f"{why}</li>")
    none = t[t["mode"] == ""]
    if len(none):
        items.append(f"<li>read at no mode (their band holds none, or no record): {html.escape(', '.join(map(str, none['run_id'])))}</li>")
    return "<p><b>Modes</b> (one calibration per assembly and mode)</p><ul>" + "".join(items) + "</ul>"


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
