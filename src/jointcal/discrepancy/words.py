"""The diagnosis in words: what is missing, what to check, and every number in agreement with the verdict.

Three verdicts (`rule.decide`, then the time-domain check of `stage.diagnose`):

* a name (one effect, or two found by forward selection): the advice of each effect, the
  time-domain E before and after (and, when it did not fall, that the time simulation
  does not confirm the name), the fingerprints for it, the parameters with intervals;
* ``none``: the held-out score, the time-domain E of the calibrated model and, when that E
  is above the 'none' threshold, that the joint parameters (not a missing effect) were off
  and the refit model's E;
* ``unexplained``: the held-out score and the time-domain E (and whether they disagree),
  everything tried (single effects and pairs, with the fingerprints against each), the
  fast model's floor, and the fingerprints that point outside the library.

The fast model's floor (its own error on the calibrated model, `floor.fast_floor`) is
stated in every verdict.
"""
from __future__ import annotations

from collections.abc import Mapping

from ..effects import EFFECTS
from .drive import refits_slope
from .rule import FLOOR_HIGH, HIGH_SCORE, NONE_E

__all__ = ["diagnosis_markdown"]


def _sentence(s: str) -> str:
    return s[0].upper() + s[1:] + ("" if s.endswith(".") else ".")


def _floor(d: Mapping) -> str:
    fl = d.get("fast_model_floor") or {}
    if fl.get("E") is None:
        return "The fast model's own error could not be measured (no time-simulated frames of the calibrated model)."
    unit = d.get("level_unit", "g")
    per = ", ".join(f"{k} {unit}: {v:.2f}" for k, v in fl.get("per_level", {}).items())
    what = fl.get("what", "its envelopes against the time simulation of the same model, same runs and bins")
    return (f"The fast model's own error on the calibrated model ({what}) is E = {fl['E']:.2f}" + (f" ({per})" if per else "") + ": "
            + ("well below the repeat scatter, so the held-out scores measure the model, not the fast model."
               if fl["E"] <= 0.5 else "a share of the scores above is the fast model's own; the decision takes it out "
               "of the baseline's score." if fl["E"] <= FLOOR_HIGH else
               "as large as the repeat scatter: the confidence is capped at medium.")) + _drive(d)


def _drive(d: Mapping) -> str:
    """A voltage drive's slope refit (`drive.refine_slope`), in a sentence ('' when none was)."""
    v = d.get("voltage_drive")
    fl = (d.get("fast_model_floor") or {}).get("E")
    if v is None and d.get("level_unit") == "V" and not refits_slope("V", fl):
        return (" The voltage drive's slope is not refit: the fast model that would judge it is off its own time "
                "simulation by more than the repeat scatter; the read-out's drive is kept.")
    if not v or v["slope_refined"] == v["slope_read_out"]:
        return ""
    a, b = complex(*v["relative_slope_read_out"]), complex(*v["relative_slope_refined"])
    corner = f"a corner R / L at {1 / v['coil_x']:.2g} w_c" if v.get("coil_x") else "no inductance"
    return (f" The voltage drive's modal constant changes across the band as a coil's (x = w_c L / R = "
            f"{v.get('coil_x', 0.0):.3f}, {corner}): A' w_c / A_c = {b.real:.3f}{b.imag:+.3f}i per unit w / w_c, "
            f"not the read-out's {a.real:.3f}{a.imag:+.3f}i (the read-out's narrow window leaves the coil's phase "
            f"out): refit with the baseline (its E {v['baseline_E_read_out']:.2f} -> {v['baseline_E_refined']:.2f}), "
            "every candidate and the E after take it. A coil ties its phase slope to its magnitude tilt; a phase "
            "that turns faster is left to the channels (channel_delay).")


def _named(d: Mapping, E0: float, E1: float) -> list[str]:
    effects = d["effects"]
    c = next(c for c in d["candidates"] if c["name"] == d["effect"])
    final = d["recalibrated"]["effect_parameters"] or c["effect_parameters"]  # the advice quotes the final model
    vals = {k: v["value"] for k, v in final.items()}
    if len(effects) == 1:
        lines = [f"**Missing effect: `{effects[0]}`** (confidence {d['confidence']}).", ""]
    else:
        single = next((s for s in d["candidates"] if len(s["effects"]) == 1), None)
        lines = [f"**Two missing effects: {' and '.join(f'`{e}`' for e in effects)}** (confidence {d['confidence']}): "
                 f"together they predict the held-out runs within {c['held_out_score']:.2f}x the repeat scatter, "
                 + (f"where the best single effect (`{single['name']}`) reaches {single['held_out_score']:.2f}x."
                    if single else "where no single effect closes the gap."), ""]
    for e in effects:
        lines += [_sentence(EFFECTS[e].advice(vals)), ""]
    verb = "falls" if E1 < E0 else "does not fall"
    lines.append(f"With {'it' if len(effects) == 1 else 'them'} the validation error E (1 = the measured repeat "
                 f"scatter) {verb} from {E0:.2f} to {E1:.2f} ({(E1 / E0 - 1) * 100:+.0f}%), checked with the time "
                 "simulation driven by each run's measured reference record.")
    if d.get("time_domain_check") == "name_not_confirmed":
        lines[-1] += (" The time simulation does not confirm the name, so its confidence is low: check the "
                      "advice above before acting on it.")
    elif d.get("time_domain_check") == "name_misses":
        lines[-1] += (f" That is still above {HIGH_SCORE:g}: the effect explains part of the gap, not all of it, so "
                      "its confidence is at most medium; something else is missing too.")
    elif E0 <= NONE_E:
        lines[-1] += (f" The calibrated model was already within the 'none' threshold ({NONE_E}) in the time "
                      "domain; the effect shows in how the held-out runs are predicted, not in the overall E.")
    lines.append("")
    if c["fingerprints_for"]:
        lines += ["Evidence: " + "; ".join(c["fingerprints_for"]) + ".", ""]
    if d.get("outside_library"):
        lines += ["But something else is there too: " + d["outside_library"] + ".", ""]
    lines += [_floor(d), ""]
    bounds = {p.name: (p.lo, p.hi) for e in effects for p in EFFECTS[e].params_for(d.get("structure_scales"))}
    for k, v in d["recalibrated"]["effect_parameters"].items():
        lo, hi = v["interval_90"]
        loose = lo <= bounds[k][0] * (1 + 1e-6) or hi >= bounds[k][1] * (1 - 1e-6)
        lines.append(f"- {k} = {v['value']:.4g} {v['unit']}, 90% interval [{lo:.4g}, {hi:.4g}]"
                     + (" (reaches a bound of the library's range: the data do not pin it)" if loose else ""))
    joint = d["recalibrated"].get("joint_parameters", {})
    if joint:
        lines += ["", "The corrected joint (recalibrated with the effect; 90% intervals): " + "; ".join(
            f"{k} {v['value']:.4g} [{v['interval_90'][0]:.4g}, {v['interval_90'][1]:.4g}]" for k, v in joint.items())
            + "."]
    return lines


def _none(d: Mapping, E0: float, E1: float) -> list[str]:
    S = d["baseline"]["held_out_score"]
    lines = [f"**No missing effect**: the model predicts levels it did not see within {S:.2f}x the measured repeat "
             "scatter (fast model, held-out levels and sweep directions)"]
    if E0 <= NONE_E:
        lines[0] += f", and the time simulation of the calibrated model reproduces the measured runs with E = {E0:.2f}."
    else:
        lines[0] += (f". The time simulation of the calibration's parameters misses the measured runs (E = {E0:.2f}), "
                     f"but the same model refit on the envelopes reproduces them with E = {E1:.2f}: the calibration's "
                     "joint parameters were off, not the model; use the refit parameters below.")
    return lines + ["", _floor(d)]


def _unexplained(d: Mapping, E0: float, E1: float) -> list[str]:
    S = d["baseline"]["held_out_score"]
    if d.get("time_domain_check") == "none_contradicted":
        lines = [f"**Unexplained**: the fast model predicts the held-out levels within {S:.2f}x the repeat scatter, "
                 f"but the time simulation misses the measured runs (E = {E0:.2f} for the calibrated model, "
                 f"{E1:.2f} refit): the two disagree, so the model is not confirmed and no library effect is named."]
    else:
        lines = [f"**Unexplained**: the model predicts levels it did not see only within {S:.2f}x the repeat scatter "
                 "(fast model, held-out), and no library effect, alone or with a second one, closes the gap "
                 "decisively."]
        if E0 <= NONE_E:
            lines[0] += (f" The time simulation of the calibrated model reproduces the runs it was calibrated on "
                         f"(E = {E0:.2f}): the two disagree, and what fails is the prediction of unseen levels.")
        else:
            lines[0] += f" The time simulation agrees: E = {E0:.2f}."
    lines += ["", "What was tried (held-out score; fingerprints against):", ""]
    for c in d["candidates"]:
        lines.append(f"- `{c['name']}`: {c['held_out_score']:.2f}; "
                     + ("; ".join(c["fingerprints_against"][:2]) or "nothing against it"))
    lines += ["", _floor(d), ""]
    seen = sorted({w for c in d["candidates"] if len(c["effects"]) == 1 for w in c["fingerprints_for"]})
    lines.append("Fingerprints pointing outside the library: " + (d["outside_library"] + "." if d.get("outside_library")
                 else "none seen (no dominant even harmonic)."))
    if seen:
        lines.append("Fingerprints of library effects that were seen, yet no model with them closes the gap: "
                     + "; ".join(seen) + ".")
    lines.append("Look for an effect outside the library (a contact, a second mode, a distorting shaker) or more "
                 "than two at once.")
    return lines


def diagnosis_markdown(d: Mapping) -> str:
    """A short plain-language diagnosis a test engineer can act on (see the module notes)."""
    lines = [f"# Discrepancy diagnosis: assembly {d['assembly']}", ""]
    E0, E1 = d["metric_before"], d["metric_after"]
    if d["effect"] == "none":
        lines += _none(d, E0, E1)
    elif d["effect"] == "unexplained":
        lines += _unexplained(d, E0, E1)
    else:
        lines += _named(d, E0, E1)
    lines += ["", "| model | held-out score |", "|---|---|", f"| baseline | {d['baseline']['held_out_score']:.2f} |"]
    lines += [f"| {c['name']} | {c['held_out_score']:.2f} |" for c in d["candidates"]]
    blind = d.get("not_seen_by_decays") or {}
    if blind:  # the decay path (`decay_stage`): effects a free decay cannot show were not tried
        lines += ["", "Diagnosed from ring-downs and dwells. Not tried: "
                  + "; ".join(f"`{k}` ({v})" for k, v in blind.items()) + "."]
    return "\n".join(lines) + "\n"
