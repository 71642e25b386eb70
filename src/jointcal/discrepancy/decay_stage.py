"""The discrepancy stage for a campaign of ring-downs (and dwells): the same steps as the sweeps' (`stage`).

0. Points and floor: the backbone points of every ring-down and each level's dwells (`decays.decay_runs`),
   scaled by the read-out's own standard errors (the ring-downs read again from their records, `read_again`),
   each run's record kept for the read-out factor (`decay_readout`: the candidate's simulated decay read by the
   estimator, over its backbone; taken at each fit's start and optimum). With the factor taken at theta the
   fast model is the time simulation's read-out at theta (the validation's compared frames,
   `jointcal.validate.decay`), so its floor F is what the linearisation misses where the scores are taken
   (`fold_floor`): a candidate's fast model, its factor taken at its fit on all runs, against the time
   simulation's read-out at each held-out fold's refit, on that fold, in the same E; the smaller of the
   baseline's and the best-scoring single effect's (``of``), since a model that misses an effect bends to each
   fold, far from its fit on all runs, and that error is the model's, not the fast model's. The backbone alone against
   the calibrated model's time simulation (the floor before the factor) is reported beside it
   (``backbone_at_calibration``).
1. Candidates: the baseline and every library effect a decay can show. An effect whose parameters do not
   change the backbone (a channel delay: a free decay has no phase against a drive; a neighbouring mode: the
   read-out band-passes the mode) or that has none (a flexible fixture: no one-DOF backbone) is not tried,
   and the diagnosis says so (``not_seen_by_decays``): it must not be named from decays.
2. Each refit on the points (`decays.DecayObjective`, the read-out factor retaken at each optimum) from the
   calibration and from its other valleys (``joint_starts``: beta is held, and the Iwan alone made to follow a
   hardening backbone sits with its macroslip knee at the top amplitude, a valley a hidden stiffening's model
   does not share), scored on held-out runs (amplitude bands on request) (`decays.decay_folds`,
   `select.score_candidates`), each fold's E its predictive deviance (`select.predictive_E`: a ring-down
   has a few windows, each a few standard errors of the refit's own extrapolation from the other runs, which
   the plain E charged as the model's error); pairs by forward selection when the rule asks.
3. Decide by `rule.decide` with F; 4. recalibrate the named (or baseline) model by the calibration's GA and
   the posterior in the grown space (`recalibrate`); revalidate every run by the time simulation
   (`jointcal.validate.validate_runs`: the decays from the record's state at the cut) -> E before and after,
   and `rule.confirm`.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np
import pandas as pd

from ..calibrate.space import PARAMS, ParamSpace
from ..effects import EFFECTS, effects_of
from ..io import excitation_kind, level_unit, run_test_kind
from ..measure.testkinds.read import read_test_run
from ..validate import ValidateSettings, model_from_best, validate_runs
from ..validate.decay import PART as DECAY
from .decays import DecayObjective, DecayRun, decay_folds, decay_runs
from .fit import candidate, model_at
from .recalibrate import recalibrate
from .rule import CLAUSES, confirm, decide, needs_pairs, pair_names
from .select import score_candidates
from .settings import DiscrepancySettings

__all__ = ["diagnose_decays", "decay_floor", "fold_floor", "linearisation_error", "not_seen", "read_again", "NOT_SEEN"]

NOT_SEEN = ("its parameters do not change the free decay's backbone f(q), zeta(q) (a free decay has no phase "
            "against a drive, and the read-out band-passes the mode): it cannot be named from decays")


def not_seen(names: Sequence[str], space: ParamSpace, m: float, scales, runs: Sequence[DecayRun],
             theta: np.ndarray) -> dict[str, str]:
    """The effects of `names` a decay cannot show, with the reason: their backbone at the calibrated joint is
    the same at the bounds of every parameter of theirs, or there is none."""
    out = {}
    for name in names:
        c = candidate(name, space, m, scales)
        base = c.grown.vector(dict(zip(PARAMS, map(float, theta))), default={p.name: p.start for p in c.effect_params})
        ends = []
        for p in c.effect_params:
            for v in (p.lo, p.hi):
                th = base.copy()
                th[c.grown.index(p.name)] = v
                ends.append(th)
        obj = DecayObjective(c, runs)
        try:
            (f, z), (f0, z0) = obj.points(np.array(ends)), obj.points(base)
        except ValueError as exc:  # e.g. a flexible fixture: no one-DOF backbone
            out[name] = str(exc).split(": ", 1)[-1]
            continue
        if np.allclose(f, f0, rtol=1e-12, atol=0) and np.allclose(z, z0, rtol=1e-12, atol=0):
            out[name] = NOT_SEEN
    return out


def read_again(records: Sequence[pd.DataFrame], rows: Sequence[Mapping]) -> dict[str, pd.DataFrame]:
    """Each ring-down's windows read from its record as the modal stage and the validation read them
    (`jointcal.measure.testkinds.read.read_test_run`), for the read-out's own standard errors; run_id -> windows."""
    out = {}
    for rec, row in zip(records, rows):
        if run_test_kind(row).swept:
            continue
        try:
            w = read_test_run(dict(row), rec, excitation_kind(rec.columns), row.get("mode_hz"))["windows"]
        except ValueError:  # a record the read-out refuses: the pooled scatter stands in
            continue
        if w is not None and len(w):
            out[str(row["run_id"])] = w
    return out


def decay_floor(c, theta: np.ndarray, runs: Sequence[DecayRun], frames: Mapping[str, pd.DataFrame]) -> dict:
    """E of the backbone of `theta` against the time simulation of the same model read at the same windows.

    frames : run_id -> the validation's compared frames (`compare_decay`: part, q_meas_in, f_sim_hz,
    zeta_sim, in_range). Each run's windows take its points' scatter. Returns E, n_runs, per_run;
    E None when no run could be compared."""
    pseudo, per = [], {}
    for rid in dict.fromkeys(r.run_id for r in runs):
        fr = frames.get(rid)
        if fr is None or "part" not in fr or not (fr["part"] == DECAY).any():
            continue
        fr = fr[(fr["part"] == DECAY) & fr["in_range"].astype(bool)]
        own = [r for r in runs if r.run_id == rid]
        sf = float(np.median(np.concatenate([r.sigma_f for r in own])))
        sz = float(np.median(np.concatenate([r.sigma_zeta for r in own])))
        q, f, z = (fr[k].to_numpy(float) for k in ("q_meas_in", "f_sim_hz", "zeta_sim"))
        ok = np.isfinite(q) & np.isfinite(f) & np.isfinite(z) & (q > 0) & (z > 0)
        if ok.sum():
            run = DecayRun(q[ok], f[ok], z[ok], np.full(ok.sum(), sf), np.full(ok.sum(), sz), own[0].row, own[0].level)
            pseudo.append(run)
            per[rid] = DecayObjective(c, [run]).E(theta)
    what = ("its free-decay backbone against the time simulation of the same model's ring-downs, read by the same "
            "estimator at the same windows")
    if not pseudo:
        return {"E": None, "n_runs": 0, "per_run": {}, "what": what}
    return {"E": DecayObjective(c, pseudo).E(theta), "n_runs": len(pseudo), "per_run": per, "what": what}


def linearisation_error(lin: DecayObjective, exact: DecayObjective, theta: np.ndarray) -> float:
    """E of `lin`'s points at theta (its read-out factor taken elsewhere) against `exact`'s (the same pieces, the
    factor taken at theta: the time simulation's read-out, R1-R2), each point over its piece's scatter."""
    f, z = exact.points(theta)
    edges = np.cumsum([0] + [r.q_in.size for r in exact.runs])
    pseudo = [replace(r, f_hz=f[a:b], zeta=z[a:b]) for r, a, b in zip(exact.runs, edges[:-1], edges[1:])]
    return replace(lin, runs=tuple(pseudo)).E(theta)


def _model_words(name: str) -> str:
    """'the baseline' or 'the cubic stiffening model' (a pair: 'the elastic softening + cubic stiffening model')."""
    return "the baseline" if name == "baseline" else f"the {name.replace('_', ' ').replace('+', ' + ')} model"


def fold_floor(lin: DecayObjective, folds: Mapping[str, Sequence[int]], max_nfev: int) -> dict:
    """The fast model's own error where the held-out scores are taken: on each fold, a candidate's objective
    linearised at its full fit (`lin`, as `select` scores it) refit without the fold, against the time simulation's read-out of
    that refit on the fold (`linearisation_error`). Returns E (the RMS over the folds, as the scores) and per_fold;
    E 0 without folds (the factor is exact at its own reference)."""
    per = {}
    for name, idx in folds.items():
        train = [i for i in range(len(lin.runs)) if i not in set(idx)]
        th = lin.subset(train).fit(lin.theta_ref, starts=1, max_nfev=max_nfev).theta
        held = lin.subset(idx)
        per[name] = linearisation_error(held, held.at(th), th)
    E = float(np.sqrt(np.mean(np.square(list(per.values()))))) if per else 0.0
    return {"E": E, "per_fold": per,
            "what": (f"the fast model of {_model_words(lin.candidate.name)}, its read-out factor taken at its fit "
                     "on all runs, against the time simulation's read-out at each held-out fold's refit, on that fold")}


def _scored_json(s, c, rec=None) -> dict:
    values = c.grown.named(s.fit.theta)
    eff = {p.name: {"value": values[p.name], "unit": p.unit,
                    "interval_90": rec.interval(p.name) if rec is not None else [values[p.name]] * 2}
           for p in c.effect_params}
    return {"name": s.name, "effects": list(c.effects), "held_out_score": s.score, "E_fit": s.fit.E,
            "held_out_E_per_level": s.held_out, "effect_parameters": eff,
            "joint_parameters": c.grown.named(s.fit.theta, PARAMS), "fingerprints_for": [],
            "fingerprints_against": [], "seconds": s.seconds}


def _residuals(obj: DecayObjective, theta) -> pd.DataFrame:
    """Each point of the baseline refit: measured and model f, zeta, and their errors over the scatter."""
    rows = []
    for i, r in enumerate(obj.runs):
        f, z = obj.predict(theta, i)
        rows.append(pd.DataFrame({"run_id": r.run_id, "band": r.band, "q_in": r.q_in, "f_meas_hz": r.f_hz,
                                  "f_model_hz": f, "zeta_meas": r.zeta, "zeta_model": z,
                                  "r_f": (f / r.f_hz - 1) / r.sigma_f, "r_zeta": (z / r.zeta - 1) / r.sigma_zeta}))
    return pd.concat(rows, ignore_index=True)


def diagnose_decays(assembly: str, backbone: pd.DataFrame, modal: pd.DataFrame, best: Mapping,
                    records: Sequence[pd.DataFrame], rows: Sequence[Mapping], *, space: ParamSpace,
                    scales: Mapping[str, float] | None, settings: DiscrepancySettings = DiscrepancySettings(),
                    validate_settings: ValidateSettings = ValidateSettings(), vkw: Mapping | None = None,
                    metric_before: float | None = None, frames_before: Mapping[str, pd.DataFrame] | None = None,
                    joint_starts: Sequence[Sequence[float]] = (), log: Callable[[str], None] | None = None) -> dict:
    """Diagnose one assembly from its ring-downs and dwells; returns the diagnosis (diagnosis.json's content,
    in the sweeps' form), the residuals of the baseline refit and the validation after.

    backbone : backbone.csv's rows of the unit; modal : modal_properties.csv's rows of the unit; best : the
    calibration's ga_best.json; records, rows : the runs' records and manifest rows (with ``drive_gain`` when
    known); scales : the structure's (`fit.structure_scales`), None for the Ministack; vkw : keywords of
    `validate_runs` (settings, executor, ...); metric_before, frames_before : the validation stage's E and
    compared frames of the calibrated model (computed here when None); joint_starts : further joint
    parameter sets (6,) the named model is also refit from.
    """
    say = log or (lambda s: None)
    t0 = time.perf_counter()
    m = float(best["m"])
    kind = str(best.get("model_kind", "ministack"))
    vkw = dict(vkw or {}, settings=validate_settings)
    runs = decay_runs(backbone, modal, rows, floor_db=validate_settings.floor_db,
                      floor_deg=validate_settings.floor_deg, se=read_again(records, rows),
                      records={str(r["run_id"]): rec for rec, r in zip(records, rows)})
    if len({r.run_id for r in runs}) < 2:
        raise ValueError(f"assembly {assembly}: {len({r.run_id for r in runs})} run(s) with backbone points; the "
                         "discrepancy workflow needs at least two ring-downs (or levels of dwells) to score held-out "
                         "runs.")
    theta0 = np.array([best[p] for p in PARAMS], dtype=float)
    names = [n for n in settings.candidates if kind in EFFECTS[n].kinds]
    blind = not_seen(names, space, m, scales, runs, theta0)
    names = [n for n in names if n not in blind]
    say(f"{assembly}: {len(runs)} pieces of {len({r.run_id for r in runs})} decays, "
        f"{sum(r.q_in.size for r in runs)} points; not tried from decays: {', '.join(blind) or 'none'}")
    if frames_before is None or metric_before is None:
        v0 = validate_runs([model_from_best(best) for _ in rows], records, rows, **vkw)
        frames_before = v0.frames if frames_before is None else frames_before
        metric_before = float(v0.error["E"]) if metric_before is None else metric_before
    c0 = candidate("baseline", space, m, scales)
    folds = decay_folds(runs)
    ex = vkw.get("executor")  # the pool the revalidation uses: the candidates fitted side by side on it too
    kw = dict(objective=DecayObjective, folds=folds, log=say, predictive=True, executor=ex)
    # every candidate from the calibration and from its other valleys: beta is held at the start's value, and the
    # Iwan alone made to follow a hardening backbone sits with its macroslip knee at the top amplitude, a valley a
    # hidden stiffening's model does not share (its read-out there is the knee's, not the backbone's)
    valleys = [theta0, *(np.asarray(th, dtype=float) for th in joint_starts)]
    singles = [c0] + [candidate(n, space, m, scales) for n in names]
    scored = score_candidates(singles, runs, theta0, max_nfev=settings.max_nfev,
                              starts={c.name: valleys for c in singles}, **kw)
    base = next(s for s in scored if s.name == "baseline")
    lin = DecayObjective(c0, runs).at(base.fit.theta)  # the baseline's objective as its held-out folds used it
    # a model that misses an effect bends to each fold's runs, refit far from its fit on all runs, where the factor
    # taken at that fit no longer holds: the model's error, not the fast model's; the floor is the smaller of the
    # baseline's and the best-scoring single effect's
    floors = {"baseline": fold_floor(lin, folds, settings.max_nfev)}
    best = min((s for s in scored if s.name != "baseline"), key=lambda s: s.score, default=None)
    if best is not None:
        cb = candidate(best.name, space, m, scales)
        floors[best.name] = fold_floor(DecayObjective(cb, runs).at(best.fit.theta), folds, settings.max_nfev)
    of = min(floors, key=lambda k: floors[k]["E"])
    floor = {**floors[of], "of": of, "per_candidate": {k: v["E"] for k, v in floors.items()},
             "backbone_at_calibration": decay_floor(c0, theta0, runs, frames_before)}
    F = floor["E"]
    say(f"{assembly}: the fast model's floor against the time simulation E = {F:.2f} (the backbone alone at the "
        f"calibration: {floor['backbone_at_calibration']['E'] or 0.0:.2f})")
    pairs_tried = []
    if needs_pairs(scored, F):
        pairs_tried = pair_names(scored, names)
        fits = {s.name: s.fit.theta for s in scored}
        scored += score_candidates([candidate(n, space, m, scales) for n in pairs_tried], runs, theta0,
                                   max_nfev=2 * settings.max_nfev, baseline=base,
                                   starts={n: [fits[effects_of(n)[0]]] for n in pairs_tried}, **kw)
    decision = decide(scored, None, floor=F)
    named = next((s for s in decision.ranked if s.name == decision.effect), base)
    cf = candidate(named.name, space, m, scales)
    starts = [named.fit] + [DecayObjective(cf, runs).fit(
        cf.grown.vector(dict(zip(PARAMS, map(float, th))), default=cf.grown.named(named.fit.theta)), starts=1,
        max_nfev=2 * settings.max_nfev) for th in joint_starts]
    rec = recalibrate(cf, runs, starts, seed=settings.seed, generations=settings.ga_generations,
                      steps=settings.posterior_steps, max_nfev=2 * settings.max_nfev, objective=DecayObjective,
                      executor=ex)
    say(f"{assembly}: decision {decision.effect} ({decision.confidence}); {named.name} recalibrated, "
        f"E {rec.fit.E:.2f}; revalidating with the time simulation")
    v_after = validate_runs([model_at(cf, rec.fit.theta, r) for r in rows], records, rows, **vkw)
    metric_after = float(v_after.error["E"])
    effect, confidence, note = confirm(decision.effect, decision.confidence, float(metric_before), metric_after)
    after = cf.grown.named(rec.fit.theta)
    diagnosis = {
        "assembly": assembly, "model_kind": kind, "structure_scales": scales, "data": "decays",
        "level_unit": level_unit(modal.columns),
        "effect": effect, "effects": list(effects_of(effect)) if effect not in ("none", "unexplained") else [],
        "confidence": confidence, "rule": decision.rule,
        "rule_applied": [*decision.applied, *([CLAUSES[note]] if note else [])], "outside_library": None,
        "not_seen_by_decays": blind, "fast_model_floor": floor, "time_domain_check": note,
        "baseline": {"held_out_score": base.score, "E_fit": base.fit.E, "held_out_E_per_level": base.held_out,
                     "joint_parameters": c0.grown.named(base.fit.theta, PARAMS)},
        "candidates": [_scored_json(s, candidate(s.name, space, m, scales)) for s in decision.ranked],
        "pairs_tried": pairs_tried, "fingerprints": {}, "metric_before": float(metric_before),
        "metric_after": metric_after, "metric_change": metric_after / metric_before - 1.0 if metric_before else None,
        "recalibrated": {"model": named.name, "E_fit": rec.fit.E,
                         "joint_parameters": {p: {"value": after[p], "interval_90": rec.interval(p)} for p in PARAMS},
                         "effect_parameters": {p.name: {"value": after[p.name], "unit": p.unit,
                                                        "interval_90": rec.interval(p.name)}
                                               for p in cf.effect_params},
                         "method": (f"DEAP GA ({rec.ga_generations} generations, best E {rec.ga_best_E:.3g}) seeded "
                                    f"with {len(starts)} least-squares fits on the decays' backbone points, polished; "
                                    f"emcee {rec.steps} steps x {rec.walkers} walkers, max tau {rec.tau_max:.0f}"),
                         "posterior_converged": rec.converged},
        "calibration_joint_parameters": dict(zip(PARAMS, map(float, theta0))),
        "words_after": v_after.words, "seconds": time.perf_counter() - t0,
    }
    return {"diagnosis": diagnosis, "residuals": _residuals(lin, base.fit.theta),
            "validation_after": v_after}
