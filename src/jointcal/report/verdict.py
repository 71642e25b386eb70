"""The verdict of the whole run, in the order a test engineer asks, and what the data identify.

Pure functions from the stages' outputs to HTML fragments of the report's summary and landing page:

1. Does the paper's model reproduce the measured envelopes? The validation stage's E
   (1 = the repeat scatter, or each run's own noise without repeats,
   `jointcal.validate.error.closeness`) and the chi-square test of the calibrated
   frequencies and damping ratios against their noise scales (``chain.npz``). The first
   word is Yes only when every test shown passes: E within `HOLDS_E` and the chi-square
   not rejecting (`first_answer`).
2. What did the discrepancy stage name, and what did the correction change (E before and
   after, ``diagnosis.json`` read as it is)?
3. The identified quantities of the model that holds: the corrected one where an effect
   was named and brings E within the scatter, else the paper's. Which quantities the data
   identify comes from the posterior (``identified.csv``, `jointcal.posterior.identified`);
   the corrected model's values and intervals from ``diagnosis.json``, and which of its
   parameters the runs identify from the read-outs at its point
   (`jointcal.posterior.identified.identified_at`). Quantities the data leave to the bounds
   are named, never given a value.
4. The next test (``next_test.json``).
"""
from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ..calibrate.space import PARAMS
from ..discrepancy.rule import FLOOR_HIGH
from ..effects import EFFECTS
from ..posterior.noise import scale_words as noise_words
from ..posterior.stage import P_REJECT
from ..validate.error import closeness, scale_source, scale_words
from .summary import fmt as _g, p_value

__all__ = ["HOLDS_E", "first_answer", "named_effects", "corrected_holds", "verdict_items", "identified_html",
           "verdict_html"]

HOLDS_E = 2.0  # a model holds when its E is "about as close as a repeated test" (closeness)
_WORDS = {"K0": "K0 = k + KT", "R": "R (eq. 3.5)", "D_ref": "dissipation per cycle at q_ref",
          "dissipation_exponent": "dissipation exponent chi + 3", "KT/k": "KT/k split", "phi_max": "phi_max (eq. 3.7)"}


def _interval(lo: float, hi: float, unit: str = "") -> str:
    u = "" if unit in ("", "-") else f" {unit}"
    return f"[{_g(lo)}, {_g(hi)}]{u}"


def _sentence(s: str) -> str:
    return s[0].upper() + s[1:] + ("" if s.endswith(".") else ".")


def named_effects(diagnosis: Mapping[str, Any]) -> list[str]:
    """The effects a diagnosis named (a list, also from a diagnosis that names one effect by its ``effect``)."""
    if "effects" in diagnosis:
        return [str(e) for e in diagnosis["effects"]]
    effect = str(diagnosis.get("effect", "none"))
    return [] if effect in ("none", "unexplained") else [effect]


def _label(row: pd.Series) -> str:
    name = str(row["quantity"])
    if row["kind"] == "curve":
        base, _, where = name.partition("(")
        return f"{'f' if base == 'f' else 'zeta'} at q = {_g(float(row['q_in']))} in ({where.rstrip(')')})"
    return _WORDS.get(name, name)


def _unit(row: pd.Series) -> str:
    return "" if row["unit"] == "-" else str(row["unit"])


def first_answer(validation: Mapping | None, fit: Mapping | None) -> bool | None:
    """Yes (True) only when every test shown passes: E within `HOLDS_E` and the chi-square test of the
    frequencies and damping not rejecting (p >= `P_REJECT`); None when neither test ran."""
    tests = []
    if validation is not None:
        tests.append(float(validation["E"]) <= HOLDS_E)
    if fit is not None and np.isfinite(fit.get("fit_p", np.nan)):
        tests.append(float(fit["fit_p"]) >= P_REJECT)
    return all(tests) if tests else None


def _item1(best: Mapping, validation: Mapping | None, fit: Mapping | None) -> str:
    kind = "the paper's model" if best.get("model_kind", "ministack") == "ministack" else "the calibrated mode"
    answer = first_answer(validation, fit)
    if answer is None:
        return "The validation stage did not run, and the posterior has no chi-square test."
    word = "<b>Yes</b>" if answer else "<b>No</b>"
    e_text = chi_text = ""
    e_ok = chi_ok = None
    if validation is not None:
        E, src = float(validation["E"]), scale_source(validation.get("scale"))
        e_ok = E <= HOLDS_E
        e_text = f"E = <b>{E:.2f}</b> (1 = {scale_words(src)}): {closeness(E, src)}"
    if fit is not None and np.isfinite(fit.get("fit_p", np.nan)):
        p = float(fit["fit_p"])
        sources = tuple(str(v) for v in fit.get("noise_source", ("repeats", "repeats")))
        chi_ok = p >= P_REJECT
        chi_text = (f"{'agree with' if chi_ok else 'are rejected by'} "
                    f"{'the repeats' if sources == ('repeats', 'repeats') else noise_words(sources)}: chi-square "
                    f"{_g(float(fit['fit_chi2']))} for {int(fit['fit_dof'])} degrees of freedom, p = {p_value(p)}"
                    f"{'' if chi_ok else ' (the model, not noise, sets the misfit)'}")
    if e_ok is False or e_ok is None and chi_ok is False or e_ok and chi_ok is not False:
        # the first test shown carries the answer (E, else the chi-square), the other agrees or adds to it
        parts = [f"{word}: {kind} against the measured envelopes, {e_text}." if e_text else
                 f"{word}: {kind}'s frequencies and damping ratios {chi_text}."]
        if e_text and chi_text:
            parts.append(f"Its calibrated frequencies and damping ratios {chi_text}"
                         + ("; the misfit lies in the envelopes, not in the backbone's frequencies and damping."
                            if chi_ok and not e_ok else "."))
    else:  # E within its scale, the chi-square rejecting: No, for the chi-square's reason
        parts = [f"{word}: {kind}'s frequencies and damping ratios {chi_text}.",
                 f"The envelopes alone do not show this misfit: {e_text}."]
    if validation is None:
        parts.append("(The validation stage did not run.)")
    return " ".join(parts)


def _item2(diagnosis: Mapping | None, best: Mapping) -> str:
    if diagnosis is None:
        return "The discrepancy stage did not run."
    E0, E1 = float(diagnosis["metric_before"]), float(diagnosis["metric_after"])
    effects = named_effects(diagnosis)
    if effects:
        rec = diagnosis.get("recalibrated", {})
        pars = "; ".join(f"{html.escape(k)} {_g(v['value'])} {_interval(*v['interval_90'], v.get('unit', ''))}"
                         for k, v in rec.get("effect_parameters", {}).items())
        vals = {k: v["value"] for k, v in rec.get("effect_parameters", {}).items()}
        means = " ".join(html.escape(_sentence(EFFECTS[e].advice(vals))) for e in effects
                         if e in EFFECTS and all(p.name in vals for p in EFFECTS[e].params))
        return (f"It names <b>{html.escape(' + '.join(effects))}</b> (confidence {html.escape(str(diagnosis.get('confidence')))})"
                + (f": {pars}" if pars else "") + f". With it E goes from <b>{E0:.2f}</b> to <b>{E1:.2f}</b> "
                f"({closeness(E1)}), checked with the time simulation driven by each run's measured reference record."
                + (f" What it means: {means}" if means else ""))
    if diagnosis.get("effect") == "none":
        return (f"No missing effect: the paper's model predicts the levels it did not see within the scatter "
                f"(E = {E0:.2f}).{_floor_words(diagnosis)}")
    refit = (f" Refit by this stage on the runs' own uncertainties, the paper's model itself comes to E = {E1:.2f}: "
             f"that much of the misfit lies in how the calibration weighs its points (eq. 3.9: relative errors, "
             f"frequency against damping), not in missing physics." if E1 < REFIT_SHARE * E0 else "")
    return (f"Unexplained: no library effect closes the gap decisively (E = {E0:.2f}); "
            + html.escape(str(diagnosis.get("outside_library") or "look for a second effect or one outside the library"))
            + "." + refit + _floor_words(diagnosis))


REFIT_SHARE = 0.5  # an 'unexplained' whose own refit of the paper's model halves E says so


def _floor_words(diagnosis: Mapping) -> str:
    """A sentence on the fast model's own error when it is above the repeat scatter (`rule.FLOOR_HIGH`), else ""."""
    floor = (diagnosis.get("fast_model_floor") or {}).get("E")
    if floor is None or float(floor) <= FLOOR_HIGH:
        return ""
    return (f" The fast envelope model the stage scores with is itself E = {float(floor):.2f} from the time "
            f"simulation of the calibrated model on these runs, so an effect smaller than that cannot be told apart "
            f"here; slower sweeps bring that floor down.")


def corrected_holds(diagnosis: Mapping | None) -> bool:
    """An effect was named and the corrected model's E is within the scatter (`HOLDS_E`) and below the paper's."""
    return bool(diagnosis and named_effects(diagnosis) and float(diagnosis["metric_after"]) <= HOLDS_E
                and float(diagnosis["metric_after"]) < float(diagnosis["metric_before"]))


def _why_not(identified: pd.DataFrame) -> str:
    """The chain's reason for identifying nothing (`jointcal.posterior.identified.unsettled`), or ""."""
    if "why_not" not in identified:
        return ""
    w = identified["why_not"].fillna("").astype(str)
    return str(w[w != ""].iloc[0]) if (w != "").any() else ""


def _item3(identified: pd.DataFrame, diagnosis: Mapping | None, corrected: Mapping[str, bool] | None,
           rejected: bool = False) -> str:
    t = identified
    free = [str(r["quantity"]) for _, r in t.iterrows() if not r["identified"] and r["kind"] != "curve"]
    if corrected_holds(diagnosis) and corrected is not None:
        rec = diagnosis["recalibrated"]["joint_parameters"]  # type: ignore[index]
        units = dict(zip(t["quantity"], t["unit"]))
        fixed = [p for p in PARAMS if corrected.get(p) and p in rec]
        loose = [p for p in PARAMS if not corrected.get(p)]
        vals = "; ".join(f"{p} {_g(rec[p]['value'])} {_interval(*rec[p]['interval_90'], units.get(p, ''))}"
                         for p in fixed)
        spurious = [p for p in loose if p in rec and not np.isclose(*rec[p]["interval_90"])]
        note = (f" The discrepancy stage's recalibration gives {', '.join(spurious)} intervals, but the runs' read-outs "
                "are flat along them at the repeat scatter, so they are not quoted." if spurious else "")
        return (f"Model that holds: the paper's with {html.escape(' + '.join(named_effects(diagnosis)))}. "  # type: ignore[arg-type]
                f"Identified (its recalibration's values, 90% intervals): {vals or 'none of the joint parameters'}. "
                f"Left to the bounds (no value is given): {', '.join(loose) or 'nothing'}. Its K0 = k + KT, R and "
                "curves are not in diagnosis.json (per-parameter intervals only); the paper's model's follow below, "
                "biased by the missing effect." + note)
    rows = [r for _, r in t.iterrows() if r["identified"] and r["kind"] != "curve"]
    vals = "; ".join(f"{_label(r)} {_g(r['median'])} {_interval(r['q05'], r['q95'], _unit(r))}" for r in rows)
    curves = t[(t["kind"] == "curve") & t["identified"]]
    cw = ""
    f = curves[curves["quantity"].str.startswith("f(")]
    z = curves[curves["quantity"].str.startswith("zeta(")]
    if len(f) and len(z):
        cw = (f" Over the measured amplitudes {_g(f['q_in'].min())} to {_g(f['q_in'].max())} in the frequency falls "
              f"from {_g(f['median'].iloc[0])} {_interval(f['q05'].iloc[0], f['q95'].iloc[0])} to "
              f"{_g(f['median'].iloc[-1])} {_interval(f['q05'].iloc[-1], f['q95'].iloc[-1])} Hz and the damping "
              f"ratio rises from {_g(z['median'].iloc[0])} {_interval(z['q05'].iloc[0], z['q95'].iloc[0])} to "
              f"{_g(z['median'].iloc[-1])} {_interval(z['q05'].iloc[-1], z['q95'].iloc[-1])}.")
    why = _why_not(t)
    free_words = (f" {html.escape(why)}" if why else
                  f" Left to the bounds (no value is given): {', '.join(_WORDS.get(n, n) for n in free)}."
                  if free else " Every parameter is identified.")
    caveat = (" These are the values of a model the tests of item 1 reject: the closest Iwan joint to the data, "
              "biased by what it misses." if rejected and vals else "")
    return f"Identified (posterior median, 90% interval): {vals or 'nothing'}.{cw}{free_words}{caveat}"


def _not_applicable(next_test: Mapping, identified: pd.DataFrame | None) -> str:
    """Item 4 for a campaign the design cannot plan (force- or voltage-driven), in agreement with item 3."""
    text = "<b>No level recommended.</b> " + html.escape(str(next_test.get("reason", "")))
    if identified is None:
        return text + " " + html.escape(str(next_test.get("what_would_identify", "")))
    why = _why_not(identified)
    free = [str(r["quantity"]) for _, r in identified.iterrows() if r["kind"] == "parameter" and not r["identified"]]
    pm = next_test.get("phi_max_interval_in") or [np.nan, np.nan]
    q_max = float(next_test.get("largest_amplitude_in", np.nan))
    if why:
        return (text + " Settle the posterior first (item 3 says what to run): until then no amplitude can be "
                "chosen to identify a parameter.")
    if not free:
        return text + " The data identify every parameter of the joint; no further level is needed for that."
    if np.isfinite(q_max) and np.isfinite(pm[1]) and q_max > pm[1]:
        return (text + f" The runs already reach {_g(q_max)} in, past the posterior's macroslip onset (phi_max "
                f"{_interval(pm[0], pm[1])} in), yet leave {', '.join(free)} to the bounds: a higher level will not "
                "identify them.")
    return text + " " + html.escape(str(next_test.get("what_would_identify", "")))


def _item4(next_test: Mapping | None, identified: pd.DataFrame | None = None) -> str:
    if next_test is None:
        return "The design stage did not run."
    r = next_test.get("recommended")
    if not r:
        return _not_applicable(next_test, identified)
    tg = next_test.get("targets", [])
    head = (f"<b>{r['level_g']:g} g base sweep, {r['direction']}, at {r['sweep_rate_hz_per_s']:g} Hz/s</b> "
            f"({r['duration_s']:.1f} s).")
    if not tg:
        return head + " The data identify every parameter; this test narrows the intervals most."
    share = float(next_test["share_of_draws_identifying_targets"])
    wn, ri = next_test["width_now"], next_test["predicted_width_ratio_if_identified"]
    parts = [f"{n} from within a factor {10 ** wn[n]:.3g} to {10 ** (wn[n] / ri[n]):.3g} (width ratio {_g(ri[n])})"
             for n in tg if np.isfinite(ri.get(n, np.nan))]
    names = " and ".join(tg)
    cond = (f"It identifies {names} at {100 * share:.0f}% of the posterior draws" if next_test.get("identifies_targets")
            else f"No level up to the shaker limit ({next_test.get('max_level_g', float('nan')):g} g) identifies {names} at "
            f"{100 * float(next_test.get('confidence', 0.9)):.0f}% of the posterior draws; this one does at the largest "
            f"share, {100 * share:.0f}% (where macroslip starts below the amplitude it reaches)")
    return (head + f" {cond}. Where it does: " + "; ".join(parts) + ". Expected width ratios (90% width now over "
            "after) over all draws: " + ", ".join(f"{n} {_g(v)}" for n, v in next_test["predicted_width_ratio"].items())
            + ". Predicted with the paper's model's posterior; details in 6. Next test.")


def verdict_items(*, best: Mapping, identified: pd.DataFrame, validation: Mapping | None = None,
                  fit: Mapping | None = None, diagnosis: Mapping | None = None, next_test: Mapping | None = None,
                  corrected: Mapping[str, bool] | None = None) -> list[tuple[str, str]]:
    """The four verdict items of one assembly: (question, answer as HTML).

    ``corrected``: which joint parameters the runs identify at the corrected model's point
    (`jointcal.posterior.identified.identified_at`), when the discrepancy stage named an effect.
    """
    rejected = first_answer(validation, fit) is False and not corrected_holds(diagnosis)
    return [("Does the paper's model reproduce the measured envelopes?", _item1(best, validation, fit)),
            ("What did the discrepancy stage name, and what did the correction change?", _item2(diagnosis, best)),
            ("What do the data identify (the model that holds)?", _item3(identified, diagnosis, corrected, rejected)),
            ("The next test", _item4(next_test, identified))]


def identified_html(identified: pd.DataFrame, *, title: str) -> str:
    """A compact table of every candidate quantity: identified ones with median and 90% interval, the others
    named as left to the bounds (their 90% range shown as a range, not a value)."""
    rows = [f"<p><b>{html.escape(title)}</b></p><table class='ident'><tr><th>quantity</th><th>identified?</th>"
            "<th>posterior median [90% interval]</th><th>share of its variance along free directions</th></tr>"]
    why = _why_not(identified)
    for _, r in identified.iterrows():
        u = _unit(r)
        if r["identified"]:
            cell = f"{_g(r['median'])} {_interval(r['q05'], r['q95'], u)}"
            flag = "<span class='good'>yes</span>"
        elif why and str(r.get("why_not", "") or ""):
            cell = (f"<i>not from this chain alone</i> (its draws span {_g(r['q05'])} to {_g(r['q95'])}"
                    f"{' ' + u if u else ''}; see below)")
            flag = "<span class='bad'>no</span>"
        else:
            cell = (f"<i>left to the bounds</i> (posterior spans {_g(r['q05'])} to {_g(r['q95'])}"
                    f"{' ' + u if u else ''}, set by the bounds, not the data)")
            flag = "<span class='bad'>no</span>"
        rows.append(f"<tr><td class='lab'>{html.escape(_label(r))}</td><td>{flag}</td><td class='lab'>{cell}</td>"
                    f"<td>{float(r['free_share']):.2f}</td></tr>")
    rows.append("</table>")
    if why:
        rows.append(f"<p class='bad'>{html.escape(why)}</p>")
    return "\n".join(rows)


def verdict_html(items: Mapping[str, Sequence[tuple[str, str]]], *, landing: bool = False) -> str:
    """Per assembly the four items, numbered: the summary page's opening (with the questions) or, with
    ``landing``, the landing text's (answers only, left-aligned in Snakemake's centred landing page)."""
    out = (['<div style="font-size:13px;line-height:1.35;text-align:left">'] if landing
           else ["<h3>Verdict of this run</h3>"])
    for name, its in items.items():
        out.append(f"<div><b>{html.escape(name)}</b></div><ol style='margin-top:0'>" if landing
                   else f"<p><b>Assembly {html.escape(name)}</b></p><ol class='verdict'>")
        out += [f"<li>{a}</li>" if landing else f"<li><b>{html.escape(q)}</b> {a}</li>" for q, a in its]
        out.append("</ol>")
    return "\n".join(out + (["</div>"] if landing else [])) + "\n"
