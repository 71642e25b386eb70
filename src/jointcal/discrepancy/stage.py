"""The discrepancy stage for one assembly: localise, score the library, decide, act, report.

0. Floor: the fast model's own error on the calibrated model, against the validation's
   time simulation of it on the same runs and bins (`floor.fast_floor`).
   A voltage drive: the slope of its modal constant A(w) refit, as a coil's (one constant,
   L / R: its phase slope tied to its magnitude tilt), with the baseline on the envelope
   frames (`drive.refine_slope`: the read-out's leaves most of the coil's phase slope out);
   every later step takes the refined drive. Each single effect that fits better than the
   baseline has the coil refit with it and is scored again there; the best on its own drive
   leads, and the single effects are scored again on its drive before forward selection
   decides whether a second effect is needed (`_lead_on_its_drive`); when a pair then scores
   best, the coil is refit with that pair and the library scored again; a named model refits
   it once more before its recalibration (the baseline's misfit moves the coil it finds). Not
   where the floor is above the repeat scatter (`rule.FLOOR_HIGH`): the fast model that
   judges the slope is then further from its record than the slope moves it.
1. Localise: the baseline (the calibration's optimum, refit on the envelopes) against
   the measured envelopes; residual map and fingerprints (`fingerprints`).
2. Candidates: the baseline and every library effect (`jointcal.effects.library()`), each refit on
   the envelopes through the fast model (`fit`), scored on held-out levels (`select`);
   when no single effect brings the score to the scatter, pairs by forward selection.
3. Decide by `rule.decide` (`rule.RULE`), which returns the clauses that decided.
4. Act: the named model recalibrated with the joint parameters (`recalibrate`:
   DEAP GA over the grown space seeded with the least-squares fits from the calibration's
   optimum and its other valleys, polish, emcee posterior for the 90% intervals),
   revalidated by the TIME simulation driven by each run's measured reference record
   (`jointcal.validate.validate_runs`, the validation stage's E: same definition, same
   runs) -> metric_before, metric_after. A 'none' that the time simulation contradicts
   (E above `rule.NONE_E` before and after) becomes 'unexplained'; a name the time
   simulation does not confirm (E not lower after) keeps confidence low.

The stage's process pool (`executor`, the rule's threads) takes the time simulations, the candidates of each
scoring pass (`select.score_candidates`), the singles' drive refits, the valley refits and half of each batch of the
recalibration's GA and chain (`recalibrate`); every number is the one the stage computes without it.

A campaign of ring-downs and dwells alone (no sweep) takes the same steps on its backbone points
(`decay_stage.diagnose_decays`: each candidate's free-decay backbone, held-out runs, the same rule,
recalibration and time-domain revalidation of the decays).
"""
from __future__ import annotations

import json
import time
from functools import partial
from dataclasses import replace
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from ..calibrate.space import PARAMS, ParamSpace
from ..effects import EFFECTS, effects_of
from ..calibrate.kind import backbone_at
from ..io import level_column, level_unit, run_test_kind
from ..io.contract import LEVEL
from ..validate.drive import drive_gain
from ..validate.testkinds import as_read
from ..measure.envelopes import ZETA_MIN
from ..posterior.sampler import TAU_FACTOR
from ..validate import ValidateSettings, model_from_best, validate_runs
from .data import run_envelope, scale_arrays
from .decay_stage import diagnose_decays
from .drive import refine_slope, refits_slope
from .fingerprints import fingerprints, outside_library, residual_map, verdicts
from .fit import Objective, candidate, model_at, structure_scales
from .floor import fast_floor
from .recalibrate import recalibrate
from .rule import CLAUSES, confirm, decide, needs_pairs, pair_bases, pair_names
from .settings import DiscrepancySettings
from .select import score_candidates, side_by_side
from .words import diagnosis_markdown

__all__ = ["DiscrepancySettings", "diagnose", "diagnosis_markdown", "valley_starts", "run_discrepancy"]


def valley_starts(history: pd.DataFrame, best: Mapping, *, n: int = 3, rel: float = np.inf) -> list[list[float]]:
    """The GA's best individual in each half-decade of Fs other than the optimum's (within `rel` x the
    best objective), the n best of them: joint starts (Fs, KT, chi, beta, k, zeta_v) from other valleys.
    A missing effect biases eq. 3.9 itself, so a valley it ranks far worse may fit the envelopes best."""
    h = history.dropna(subset=list(PARAMS) + ["objective"])
    h = h[h["objective"] <= rel * h["objective"].min()]
    if h.empty:
        return []
    bins = np.floor(2 * np.log10(h["Fs"].to_numpy()))
    own = np.floor(2 * np.log10(float(best["Fs"])))
    picks = h.assign(bin=bins)[bins != own].sort_values("objective").groupby("bin").head(1)
    return picks.sort_values("objective")[list(PARAMS)].head(n).to_numpy().tolist()


def _interval(fit, c, name) -> list[float]:
    """Approximate 90% interval of parameter `name` (physical units) from the unit-cube covariance."""
    i = c.grown.index(name)
    sd = np.sqrt(max(fit.cov_unit[i, i], 0.0))
    u = c.to_unit(fit.theta)
    lo, hi = u.copy(), u.copy()
    lo[i] = max(0.0, u[i] - 1.645 * sd)
    hi[i] = min(1.0, u[i] + 1.645 * sd)
    return [float(c.to_physical(lo)[i]), float(c.to_physical(hi)[i])]


def _with_joint(c, theta, joint) -> np.ndarray:
    """Candidate c's parameters theta with the joint's replaced by `joint` (Fs, KT, chi, beta, k, zeta_v)."""
    return c.grown.vector(dict(zip(PARAMS, map(float, joint))), default=c.grown.named(theta))


def _candidate_json(s, space, m, ver, scales) -> dict:
    c = candidate(s.name, space, m, scales)
    values = c.grown.named(s.fit.theta)
    eff = {p.name: {"value": values[p.name], "unit": p.unit, "interval_90": _interval(s.fit, c, p.name)}
           for p in c.effect_params}
    return {"name": s.name, "effects": list(c.effects), "held_out_score": s.score, "E_fit": s.fit.E,
            "held_out_E_per_level": s.held_out, "effect_parameters": eff,
            "joint_parameters": c.grown.named(s.fit.theta, PARAMS),
            "fingerprints_for": fingerprint_words(c.effects, ver, "for"),
            "fingerprints_against": fingerprint_words(c.effects, ver, "against"), "seconds": s.seconds}


def fingerprint_words(effects: Sequence[str], ver: Mapping[str, Mapping[str, list]], side: str) -> list[str]:
    """The fingerprints 'for' or 'against' a candidate of these effects (`fingerprints.verdicts`), each once: a
    pair's two effects share those that point outside the library."""
    return list(dict.fromkeys(w for e in effects for w in ver[e][side]))


def diagnose(assembly: str, envs: Mapping[str, pd.DataFrame], modal: pd.DataFrame, best: Mapping,
             scale: Sequence[Mapping] | None, records: Sequence[pd.DataFrame], rows: Sequence[Mapping], *,
             space: ParamSpace, settings: DiscrepancySettings = DiscrepancySettings(),
             validate_settings: ValidateSettings = ValidateSettings(), envelopes_kw: dict | None = None,
             modal_kw: dict | None = None, metric_before: float | None = None,
             frames_before: Mapping[str, pd.DataFrame] | None = None, executor=None,
             joint_starts: Sequence[Sequence[float]] = (), log: Callable[[str], None] | None = None,
             backbone: pd.DataFrame | None = None) -> dict:
    """Diagnose one assembly; returns the diagnosis (diagnosis.json's content plus tables and models).

    Parameters
    ----------
    envs : run_id -> envelopes DataFrame; modal : modal_properties.csv rows (all assemblies);
    best : the calibration's ga_best.json; scale : the validation's repeat-scatter bins
    (summary.json's "scale"); frames_before : the validation's compared frames of the
    calibrated model (run_id -> its envelopes/<run_id>.csv); when either is None the
    calibrated model is validated here first, as the validation stage does, and its scale,
    frames and E are used; records, rows : measured records and manifest rows of the
    assembly's runs (for the time-simulation revalidation); metric_before : the validation
    stage's E (recomputed when None); joint_starts : further joint parameter sets (6,) from
    which the final model is also refit (e.g. the GA's best individual in each other valley:
    eq. 3.9 leaves the Fs-KT split flat, the envelopes may not); backbone : backbone.csv's rows of the
    assembly's runs: a campaign without sweeps (ring-downs, dwells) is diagnosed from them
    (`decay_stage.diagnose_decays`); a campaign with sweeps from the sweeps' envelopes, as before.
    """
    say = log or (lambda s: None)
    clock = _Clock()
    m = float(best["m"])
    kind = str(best.get("model_kind", "ministack"))
    settings = replace(settings, candidates=tuple(n for n in settings.candidates if kind in EFFECTS[n].kinds))
    scales = structure_scales(best, modal[modal["assembly"] == assembly]) if kind != "ministack" else None
    voltage = level_column(modal.columns) == LEVEL["voltage"]
    gain = drive_gain(modal[modal["assembly"] == assembly]) if level_column(modal.columns) != LEVEL["base"] else None
    if gain is not None:  # a force or voltage drives the mode through the campaign's modal constant
        rows = [{**r, "drive_gain": gain} for r in rows]
    mine = modal[modal["assembly"] == assembly]
    # each run read as the modal stage read it (its frequency; a decay through the force with its measured
    # constants), as the validation stage reads it: E before and after from the same read-out of the same records
    rows = as_read(rows, mine)
    if backbone is not None and not any(run_test_kind(r).swept for r in rows):  # ring-downs and dwells alone
        return diagnose_decays(assembly, backbone, mine, best, records, rows, space=space, scales=scales,
                               settings=settings, validate_settings=validate_settings,
                               vkw=dict(envelopes_kw=envelopes_kw, modal_kw=modal_kw, executor=executor),
                               metric_before=metric_before, frames_before=frames_before, joint_starts=joint_starts,
                               log=say)
    if voltage and scales is not None:  # the sweeps' shaker loop: a neighbouring mode sits in it (`neighbour_mode`)
        scales = {**scales, "voltage": 1.0}
    theta0 = np.array([best[p] for p in PARAMS], dtype=float)
    vkw = dict(settings=validate_settings, envelopes_kw=envelopes_kw, modal_kw=modal_kw, executor=executor)
    if scale is None or frames_before is None:  # as the validation stage does: the calibrated model in time
        v_before = validate_runs([model_from_best(best) for _ in rows], records, rows, **vkw)
        scale = v_before.scale.to_dict(orient="records") if scale is None else scale
        frames_before = v_before.frames
        metric_before = float(v_before.error["E"]) if metric_before is None else metric_before
    clock.lap("validate_before")
    sdb, sdeg = scale_arrays(scale)
    mrows = modal[modal["assembly"] == assembly].set_index("run_id")
    zeta_min = float((envelopes_kw or {}).get("zeta_min", ZETA_MIN))
    runs = _usable_runs(assembly, envs, mrows, rows, sdb, sdeg, settings, zeta_min)
    say(f"{assembly}: {len(runs)} usable runs, {sum(r.f_hz.size for r in runs)} envelope frames")
    c0 = candidate("baseline", space, m, scales)
    floor = fast_floor(c0, theta0, runs, frames_before, sdb, sdeg)  # the read-out's drive, as the validation's
    F = floor["E"] if floor["E"] is not None else 0.0
    say(f"{assembly}: the fast model's floor (its envelope of the calibrated model against the time simulation) "
        f"E = {F:.2f}" + ("" if floor["E"] is not None else " (no validation frames to compare: taken as 0)"))
    clock.lap("floor")
    drive, unit = None, level_unit(modal.columns)
    voltage = gain is not None and unit == "V"
    if voltage and not refits_slope(unit, F):
        say(f"{assembly}: the voltage drive's slope not refit: the fast model that would judge it is off its own "
            f"time simulation by E {F:.2f}, more than the repeat scatter")
    elif voltage:  # the coil's slope (`drive`)
        build = partial(_runs_on_drive, assembly, envs, mrows, rows, sdb, sdeg, settings, zeta_min)
        gain, runs, drive = refine_slope(c0, theta0, gain, build, max_nfev=settings.max_nfev)
        rows = [{**r, "drive_gain": gain} for r in rows]
        say(f"{assembly}: the voltage drive's slope A' w_c / A_c refit with the baseline: "
            f"{complex(*drive['relative_slope_read_out']):.3f} -> {complex(*drive['relative_slope_refined']):.3f}, "
            f"baseline E {drive['baseline_E_read_out']:.2f} -> {drive['baseline_E_refined']:.2f}")
        clock.lap("drive")
    baseline_drive = (gain, runs, rows)  # the drive the baseline refit: kept where no model is named
    lib = (assembly, space, m, theta0, settings, clock, say, scales, executor)  # the pool fits candidates side by side
    scored = _score_singles(*lib, runs)
    lead = min(scored, key=lambda s: s.score)
    if drive is not None and lead.name != "baseline":  # the baseline missed: the slope again with the single effect
        # that predicts best, and the singles scored again with it, before forward selection asks for a second
        # effect (the baseline's misfit moved the slope it found; a pair judged on that slope is partly the slope's)
        lead, gain, runs, again = _lead_on_its_drive(*lib, scored, gain, build)
        rows = [{**r, "drive_gain": gain} for r in rows]
        drive["with_best"] = {"model": lead.name, **again}
        say(f"{assembly}: the voltage drive's slope refit with {lead.name}, the single effect that scores best on "
            f"its own drive: {complex(*again['relative_slope_refined']):.3f}; the single effects scored again with it")
        scored = _score_singles(*lib, runs, prev=scored)
    scored, pairs_tried = _add_pairs(*lib, runs, scored, F, joint_starts)
    lead = min(scored, key=lambda s: s.score)
    if drive is not None and len(effects_of(lead.name)) > 1:  # a pair predicts best: the slope with it, and the
        # library (singles and pairs) scored again
        gain, runs, again = refine_slope(candidate(lead.name, space, m, scales), lead.fit.theta, gain, build,
                                         max_nfev=settings.max_nfev)
        rows = [{**r, "drive_gain": gain} for r in rows]
        drive["with_pair"] = {"model": lead.name, **again}
        say(f"{assembly}: the voltage drive's slope refit with {lead.name}, the pair that scores best: "
            f"{complex(*again['relative_slope_refined']):.3f}; the library scored again with it")
        clock.lap("drive")
        scored, pairs_tried = _add_pairs(*lib, runs, _score_singles(*lib, runs, prev=scored), F, joint_starts,
                                         prev=scored)
    base = next(s for s in scored if s.name == "baseline")
    res, fp, ver, outside = _localise(c0, base, runs, mrows, m, sdb)
    decision = decide(scored, outside, floor=F)
    effect, confidence, ranked = decision.effect, decision.confidence, decision.ranked
    named = next((s for s in ranked if s.name == effect), None)
    if drive is not None and named is not None:  # the slope again, with the model kept (the baseline's misfit moved it)
        gain, runs, again = refine_slope(candidate(named.name, space, m, scales), named.fit.theta, gain, build,
                                         max_nfev=settings.max_nfev)
        rows = [{**r, "drive_gain": gain} for r in rows]
        drive["with_named"] = {"model": named.name, **again}
        say(f"{assembly}: the voltage drive's slope refit with {named.name}: "
            f"{complex(*again['relative_slope_refined']):.3f}, its E {again['baseline_E_read_out']:.2f} -> "
            f"{again['baseline_E_refined']:.2f}")
    if drive is not None and named is None:  # nothing named: the baseline, revalidated with its own drive, not
        # the one the best-scoring candidate refit (on the real UNESP beam that one put the baseline's E at 13.3)
        gain, runs, rows = baseline_drive
        drive["revalidated_with"] = "the baseline's slope"
    final, cf, rec, n_fits = _recalibrated(assembly, named if named is not None else base, space, m, runs,
                                           joint_starts, settings, say, scales, executor)
    clock.lap("recalibrate")
    say(f"{assembly}: decision {effect} ({confidence}); revalidating with the time simulation")
    v_after = validate_runs([model_at(cf, final.fit.theta, r) for r in rows], records, rows, **vkw)
    if metric_before is None:
        metric_before = float(validate_runs([model_from_best(best) for _ in rows], records, rows, **vkw).error["E"])
    metric_after = float(v_after.error["E"])
    clock.lap("validate_after")
    effect, confidence, time_note = confirm(effect, confidence, float(metric_before), metric_after)
    diagnosis = {
        "assembly": assembly, "model_kind": kind, "structure_scales": scales, "level_unit": unit,
        "effect": effect, "effects": list(effects_of(effect)) if effect not in (
            "none", "unexplained") else [], "confidence": confidence, "rule": decision.rule,
        "rule_applied": [*decision.applied, *([CLAUSES[time_note]] if time_note else [])],
        "outside_library": outside,
        "fast_model_floor": floor, "time_domain_check": time_note, "voltage_drive": drive,
        "baseline": {"held_out_score": base.score, "E_fit": base.fit.E, "held_out_E_per_level": base.held_out,
                     "joint_parameters": c0.grown.named(base.fit.theta, PARAMS)},
        "candidates": [_candidate_json(s, space, m, ver, scales) for s in ranked], "pairs_tried": pairs_tried,
        "fingerprints": fp, "metric_before": float(metric_before), "metric_after": metric_after,
        "metric_change": metric_after / metric_before - 1.0 if metric_before else None,
        "recalibrated": _recalibrated_json(final, cf, rec, n_fits),
        "calibration_joint_parameters": dict(zip(PARAMS, map(float, theta0))),
        "words_after": v_after.words, "seconds": clock.total(), "seconds_per_step": clock.steps,
    }
    return {"diagnosis": diagnosis, "residuals": res, "validation_after": v_after}


class _Clock:
    """Seconds per step of the stage, for diagnosis.json."""

    def __init__(self) -> None:
        self.start, self.steps = time.perf_counter(), {}

    def lap(self, step: str) -> None:
        """The seconds since the last lap, added to `step`'s (a voltage drive's library is scored twice)."""
        dt = time.perf_counter() - self.start - sum(self.steps.values())
        self.steps[step] = self.steps.get(step, 0.0) + dt

    def total(self) -> float:
        return time.perf_counter() - self.start


def _usable_runs(assembly, envs, mrows, rows, sdb, sdeg, settings, zeta_min) -> list:
    """The assembly's runs with envelopes and a modal row, as `RunEnvelope`s; at least two."""
    runs = []
    for row in rows:
        rid = row["run_id"]
        if rid not in mrows.index or rid not in envs:
            continue
        r = run_envelope(envs[rid], {**dict(row), **mrows.loc[rid].to_dict(), "run_id": rid}, sdb, sdeg,
                         band=settings.band, max_frames=settings.max_frames, zeta_min=zeta_min)
        if r is not None:
            runs.append(r)
    if len(runs) < 2:
        raise ValueError(f"assembly {assembly}: {len(runs)} usable run(s); the discrepancy workflow needs at "
                         "least two usable runs (at two levels to score held-out levels).")
    return runs


def _score_singles(assembly, space, m, theta0, settings, clock, say, scales, ex, runs, prev=None):
    """The baseline and every single effect of the library, refit and scored on held-out folds (`score_candidates`).

    prev : the same candidates scored on the runs before the drive's slope was refit: each is then also refit
    from its fit there (the slope moved by a few per cent of itself; from the calibration's optimum alone a fit
    can land in a worse valley than the one it held: on a voltage campaign hiding a cubic, E 1.42 -> 1.77)."""
    cands = [candidate("baseline", space, m, scales)] + [candidate(n, space, m, scales) for n in settings.candidates]
    scored = score_candidates(cands, runs, theta0, max_nfev=settings.max_nfev, log=say, starts=_warm(theta0, prev),
                              executor=ex)
    clock.lap("singles")
    return scored


def _runs_on_drive(assembly, envs, mrows, rows, sdb, sdeg, settings, zeta_min, gain) -> list:
    """The assembly's usable runs (`_usable_runs`) with the voltage drive's modal constant `gain`."""
    return _usable_runs(assembly, envs, mrows, [{**r, "drive_gain": gain} for r in rows], sdb, sdeg, settings,
                        zeta_min)


def _on_own_drive(c, s, gain, build, theta0, base, max_nfev):
    """Scored single `s` of candidate `c` with the drive's slope refit with it: (scored, gain, runs, slope info)."""
    g, runs, info = refine_slope(c, s.fit.theta, gain, build, max_nfev=max_nfev)
    # a drive the effect leaves where it was: its score stands
    own = s if g == gain else score_candidates([c], runs, theta0, baseline=base, max_nfev=max_nfev,
                                               starts={s.name: [theta0, s.fit.theta]})[0]
    return own, g, runs, info


def _lead_on_its_drive(assembly, space, m, theta0, settings, clock, say, scales, ex, scored, gain, build):
    """A voltage drive: each single effect that fits the runs better than the baseline (E on all runs) or scores
    better, the drive's slope refit with it (`refine_slope`) and scored again on that drive; the best, as (scored,
    gain, runs, slope info). The stage asks only when a single scores better, so there is always one to refit.

    The coil's slope refit with the baseline takes up what of an effect it can: a channel delay's phase slope, as
    much as the coil's magnitude tilt lets it (on the jointed beam hiding a 400 us delay: x 0.32 against the
    rig's 0.09). Judged on that drive, the delay's held-out score was about the baseline's (2.21 and 2.42 against
    2.51 and 2.36), and a neighbouring mode, whose residual term follows the tilt so left, scored best (1.83, 1.63);
    each on its own drive, the delay scored 1.21 against the neighbour's 1.42."""
    base = next(s for s in scored if s.name == "baseline")
    best = None
    tried = sorted((s for s in scored if s.name != "baseline" and (s.fit.E < base.fit.E or s.score < base.score)),
                   key=lambda s: s.score)
    jobs = [(candidate(s.name, space, m, scales), s, gain, build, theta0, base, settings.max_nfev) for s in tried]
    done = side_by_side(ex, _on_own_drive, jobs, [len(j[0].names) for j in jobs])  # each on its own drive
    for s, (own, g, runs, info) in zip(tried, done):
        say(f"{assembly}: {s.name} on the drive refit with it ({complex(*info['relative_slope_refined']):.3f}): "
            f"held-out score {s.score:.2f} -> {own.score:.2f}")
        if best is None or own.score < best[0].score:
            best = (own, g, runs, info)
    clock.lap("drive")
    return best


def _add_pairs(assembly, space, m, theta0, settings, clock, say, scales, ex, runs, scored, F, joint_starts,
               prev=None):
    """Pairs by forward selection when no single effect closes the gap (`rule.needs_pairs`; the bases refit from the
    calibration's other valleys first): the scored candidates with them, and the pairs tried. prev : as
    `_score_singles`'s (a pair fitted there is also refit from that fit)."""
    base = next(s for s in scored if s.name == "baseline")
    pairs_tried = []
    if needs_pairs(scored, F):
        bases = pair_bases(scored)
        fits = {s.name: s.fit.theta for s in scored}
        refined = score_candidates([candidate(b, space, m, scales) for b in bases], runs, theta0, baseline=base, log=say,
                                   max_nfev=2 * settings.max_nfev, executor=ex,
                                   starts={b: [fits[b]] + [_with_joint(candidate(b, space, m, scales), fits[b], th)
                                                           for th in joint_starts] for b in bases})
        better = {r.name: r for r in refined if r.fit.E < next(s for s in scored if s.name == r.name).fit.E}
        scored = [better.get(s.name, s) for s in scored]
    if needs_pairs(scored, F):
        names = pair_names(scored, settings.candidates)
        say(f"{assembly}: no single effect closes the gap; forward selection tries {len(names)} pairs")
        fits = {s.name: s.fit.theta for s in scored}
        pc = [candidate(n, space, m, scales) for n in names]
        before = {s.name: s.fit.theta for s in prev or ()}
        scored = scored + score_candidates(pc, runs, theta0, max_nfev=2 * settings.max_nfev, log=say, baseline=base,
                                           executor=ex,
                                           starts={n: [fits[effects_of(n)[0]]] + ([before[n]] if n in before else [])
                                                   for n in names})
        pairs_tried = names
    clock.lap("pairs")
    return scored, pairs_tried


def _warm(theta0, prev) -> dict | None:
    """`score_candidates`' starts: the calibration's optimum and each candidate's fit in `prev` (None: theta0 alone)."""
    return None if prev is None else {s.name: [theta0, s.fit.theta] for s in prev}


def _localise(c0, base, runs, mrows, m, sdb):
    """Residuals of the baseline refit, the fingerprints, each effect's verdicts and what points
    outside the library."""
    res = residual_map(Objective(c0, runs).at(base.fit.theta), base.fit.theta)
    usable = mrows.loc[[r.row["run_id"] for r in runs]].reset_index()
    jb = dict(zip(PARAMS, base.fit.theta))
    f, z = backbone_at(jb, m, usable["q_in"].to_numpy(float))
    model_fz = {rid: (float(a), float(b)) for rid, a, b in zip(usable["run_id"], f, z)}
    sf = usable.groupby(level_column(usable.columns))["f_res_hz"].std().dropna() / usable["f_res_hz"].mean()
    scatter_f = float(np.sqrt(np.mean(sf**2))) if len(sf) else 1e-4
    fp = fingerprints(res, usable, model_fz, jb, max(scatter_f, 2e-5), m)
    ver = verdicts(fp, float(sdb[-1]), max(scatter_f, 2e-5))
    return res, fp, ver, outside_library(fp)


def _recalibrated(assembly, final, space, m, runs, joint_starts, settings, say, scales, ex=None):
    """The named (or baseline) model refit from the calibration's other valleys too (on the pool `ex`, side by
    side), then recalibrated (`recalibrate`: GA over the grown space, polish, emcee). Returns the scored candidate
    with the recalibrated fit, the candidate, the recalibration and the number of seeding fits."""
    cf = candidate(final.name, space, m, scales)
    starts = [_with_joint(cf, final.fit.theta, th) for th in joint_starts]
    obj = Objective(cf, runs)
    fit = partial(obj.fit, starts=1, max_nfev=2 * settings.max_nfev, refresh=1)
    alts = list(side_by_side(ex, fit, [(s,) for s in starts], [0] * len(starts)))
    for start, alt in zip(starts, alts):
        say(f"{assembly}: {final.name} refit from Fs = {cf.grown.column(start, 'Fs'):.3g} lbf: E {alt.E:.2f}")
    fits = [final.fit, *alts]
    rec = recalibrate(cf, runs, fits, seed=settings.seed, generations=settings.ga_generations,
                      steps=settings.posterior_steps, max_nfev=2 * settings.max_nfev, executor=ex)
    say(f"{assembly}: {final.name} recalibrated: GA best E {rec.ga_best_E:.2f} ({rec.ga_generations} generations), "
        f"polished E {rec.fit.E:.2f}; emcee {rec.steps} steps, tau {rec.tau_max:.0f}")
    return type(final)(final.name, rec.fit, final.score, final.held_out, final.seconds), cf, rec, len(fits)


def _recalibrated_json(final, cf, rec, n_fits) -> dict:
    """diagnosis.json's "recalibrated": the model, its joint and effect parameters with 90% intervals."""
    after = cf.grown.named(final.fit.theta)
    return {"model": final.name,
            "joint_parameters": {p: {"value": after[p], "interval_90": rec.interval(p)} for p in PARAMS},
            "E_fit": final.fit.E,
            "effect_parameters": {p.name: {"value": after[p.name], "unit": p.unit,
                                           "interval_90": rec.interval(p.name)} for p in cf.effect_params},
            "method": (f"DEAP GA ({rec.ga_generations} generations, best E {rec.ga_best_E:.3g}) seeded "
                       f"with {n_fits} least-squares fits, polished; emcee {rec.steps} steps x {rec.walkers} "
                       f"walkers, max tau {rec.tau_max:.0f} steps"
                       + ("" if rec.converged else f" (short of {TAU_FACTOR:g} tau: intervals approximate)")
                       + "; intervals are the 5-95% posterior quantiles"),
            "posterior_converged": rec.converged}


def run_discrepancy(assembly: str, *, runs_csv, modal_csv, envelope_files: Sequence[str], record_files: Sequence[str],
                    best_json, history_csv, validation_json, out: Mapping[str, str], config: Mapping[str, Mapping],
                    executor=None, log: Callable[[str], None] | None = None, backbone_csv=None) -> dict:
    """The stage for one (assembly, mode), from the files the workflow has to the files it writes.

    Reads runs.csv, this unit's modal_properties.csv, the runs' envelopes and records, the
    calibration (ga_best.json, ga_history.csv) and the validation (summary.json and its
    envelopes/ beside it), and backbone.csv (`backbone_csv`, for a campaign of ring-downs and dwells);
    `diagnose`s; writes ``out``'s diagnosis (json), markdown, residuals,
    metrics_after, residual_figure and before_after_figure. ``config`` holds the config's
    discrepancy, calibrate, validate, envelopes and modal sections. Returns the diagnosis.
    """
    from pathlib import Path

    from ..calibrate import CalibrateSettings
    from ..io import listed_record, read_run, write_bytes_atomic, write_csv_atomic, write_json_atomic
    from ..report.discrepancy import (before_after_figure, decay_before_after_figure, decay_residual_figure,
                                      residual_map_figure)

    runs = pd.read_csv(runs_csv, dtype={"flags": str})
    modal = pd.read_csv(modal_csv, dtype={"flags": str})  # this (assembly, mode)'s rows
    rows = runs[runs["run_id"].isin(modal["run_id"])].to_dict("records")
    env_dir = Path(envelope_files[0]).parent
    envs = {r["run_id"]: pd.read_csv(env_dir / f"{r['run_id']}.csv") for r in rows
            if (env_dir / f"{r['run_id']}.csv").is_file()}
    records = [read_run(listed_record(str(r["file"]), list(record_files)), r) for r in rows]
    best = json.loads(Path(best_json).read_text())
    summary = json.loads(Path(validation_json).read_text())
    space = CalibrateSettings.from_config(config.get("calibrate")).resolved(best).space
    before = {p.stem: pd.read_csv(p) for p in (Path(validation_json).parent / "envelopes").glob("*.csv")}
    res = diagnose(assembly, envs, modal, best, summary.get("scale"), records, rows, space=space,
                   settings=DiscrepancySettings.from_config(config.get("discrepancy")),
                   validate_settings=ValidateSettings.from_config(config.get("validate")),
                   envelopes_kw=dict(config["envelopes"]), modal_kw=dict(config["modal"]),
                   metric_before=float(summary["E"]), frames_before=before,
                   joint_starts=valley_starts(pd.read_csv(history_csv), best), executor=executor, log=log,
                   backbone=pd.read_csv(backbone_csv) if backbone_csv is not None else None)
    d = res["diagnosis"]
    write_csv_atomic(res["residuals"], out["residuals"])
    write_csv_atomic(res["validation_after"].metrics, out["metrics_after"])
    write_bytes_atomic(diagnosis_markdown(d).encode(), out["markdown"])
    decays = d.get("data") == "decays"
    (decay_residual_figure if decays else residual_map_figure)(res["residuals"], d, Path(out["residual_figure"]))
    (decay_before_after_figure if decays else before_after_figure)(before, res["validation_after"].frames, d,
                                                                   Path(out["before_after_figure"]))
    write_json_atomic(d, out["diagnosis"])
    return d
