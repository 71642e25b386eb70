"""Score: refit the baseline and every library candidate, score them on runs they did not fit (the
decision on those scores is `rule.decide`).

Held-out score. For each tested level L (with at least two levels), every model is refit
on the runs of the other levels (warm started from its fit on all runs) and its fast-model
E is taken on the runs of level L; likewise each sweep direction is predicted from the
runs of the other (up and down runs interleave in the sequence, so a drift with the run
sequence is judged on runs between fitted ones). The score is the RMS of those E over the
folds. A model that changes with the run sequence (`Candidate.sequence_dependent`) is not
judged on a fold whose held-out runs lie mostly outside the fitted runs' span of the
sequence (holding out the 1 g level removes the start of a Table 3.1 series: the drift would
be extrapolated backward past every fitted run); its score is the baseline's over all folds
times its RMS over ratio the baseline's on the folds it is judged on. The
held-out runs penalise flexibility (an extra parameter that only absorbs the fitted
runs' noise predicts the unseen level no better), and a further complexity penalty of
`PENALTY_PER_PARAM` (relative, per extra parameter) is applied to the score.

Forward selection. When the best single effect leaves a held-out score above `NONE_E`, or
is a drift with the run sequence found within the scatter (the drift inflates the repeat
scatter, so a second effect may hide in it) (`rule.needs_pairs`), the best single (and the
runner-up, if the best does not beat it decisively, `rule.pair_bases`) is first refit from the
calibration's other valleys too, with the effort a pair gets (a pair must not win by
the optimiser's luck alone); if it still leaves the gap, each other effect is added to it:
the pairs are fitted and scored the same way, on the same folds, with the penalty for all
their parameters (`rule.pair_names`).

The fast model's floor F (its own error against the time simulation of the calibrated model
on the same runs and bins, `floor.fast_floor`) is taken out of the baseline's score before
the 'none' test (`rule`).
"""
from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .data import RunEnvelope
from ..io import level_unit
from .fit import HELD, Candidate, Fit, Objective

__all__ = ["PENALTY_PER_PARAM", "Scored", "score_candidates", "predictive_E", "side_by_side"]

PENALTY_PER_PARAM = 0.02


@dataclass
class Scored:
    """A candidate's full fit, its held-out score and per-fold E, and the time it took."""

    name: str
    fit: Fit
    score: float
    held_out: dict = field(default_factory=dict)
    seconds: float = 0.0


def _folds(runs: Sequence[RunEnvelope]) -> dict[str, list[int]]:
    """Held-out folds: each level, each sweep direction predicted from the other, and each sweep rate from the
    others (a sweep effect, or a model that only absorbs the fitted rate's transient).

    Levels test the amplitude dependence (a model that only absorbs the fitted levels predicts
    an unseen one no better); directions interleave in the run sequence (up, down, up, ...),
    so a drift with the sequence is judged on runs between fitted ones, and a sweep effect on
    the branch it was not fitted on."""
    unit = level_unit(runs[0].row)
    levels = [r.level for r in runs]
    folds = {f"{L:g} {unit}".strip(): [i for i, v in enumerate(levels) if v == L] for L in sorted(set(levels))}
    if len(folds) < 2:
        return {}
    dirs = [str(r.row.get("direction", "")) for r in runs]
    if len(set(dirs)) > 1:
        folds.update({d: [i for i, v in enumerate(dirs) if v == d] for d in sorted(set(dirs))})
    rates = [float(r.row.get("sweep_rate_hz_per_s", np.nan)) for r in runs]  # each rate predicted from the others
    if len(set(rates)) > 1 and all(np.isfinite(rates)):
        folds.update({f"{rt:g} Hz/s": [i for i, v in enumerate(rates) if v == rt] for rt in sorted(set(rates))})
    return folds


def _extrapolates_sequence(runs: Sequence[RunEnvelope], idx: list[int]) -> bool:
    """True when most held-out runs lie outside the training runs' span of the run sequence."""
    seq = np.array([float(r.row.get("sequence", i)) for i, r in enumerate(runs)])
    train = np.delete(seq, idx)
    if train.size == 0:
        return True
    outside = (seq[idx] < train.min()) | (seq[idx] > train.max())
    return bool(outside.mean() > 0.5)


def _held_out(obj: Objective, full: Fit, max_nfev: int, folds: dict[str, list[int]],
              predictive: bool = False) -> dict[str, float]:
    """E of the candidate refit without each fold, on that fold (folds it cannot be judged on left out); the
    objective is linearised at the full fit. predictive: the fold's E as its predictive deviance
    (`predictive_E`)."""
    per = {}
    for name, idx in folds.items():
        if obj.candidate.sequence_dependent and _extrapolates_sequence(obj.runs, idx):
            continue
        train = [i for i in range(len(obj.runs)) if i not in set(idx)]
        f = obj.subset(train).fit(full.theta, starts=1, max_nfev=max_nfev)
        per[name] = (predictive_E(obj.subset(train), obj.subset(idx), f.theta) if predictive
                     else obj.subset(idx).E(f.theta))
    return per


def _unit_jacobian(obj, u: np.ndarray, idx: np.ndarray, h: float = 1e-5) -> tuple[np.ndarray, np.ndarray]:
    """An objective's residuals at the unit-cube point u and their forward-difference Jacobian in the columns
    idx: (m,), (m, k)."""
    c = obj.candidate
    r0 = obj.residuals(c.to_physical(u))
    U = np.repeat(u[None], idx.size, axis=0)
    step = np.where(u[idx] + h <= 1.0, h, -h)
    U[np.arange(idx.size), idx] += step
    return r0, ((obj.residuals(c.to_physical(U)) - r0) / step[:, None]).T


def predictive_E(train, test, theta: np.ndarray) -> float:
    """The held-out E of a model refit on `train`, at theta, as the Gaussian predictive deviance on `test`.

    A residual is r_i = w_i z_i, z_i its error in standard errors (the objective's ``weights`` w, squares
    summing to 1). The refit's parameters scatter with the fitted points' noise: linearised, with J the fitted
    residuals' Jacobian in the free unit-cube columns not on a bound (a parameter on its bound is held there),
    cov = (J^T J)^-1 J^T W^2 J (J^T J)^-1, W = diag(w). A held-out point's predictive variance in standard
    errors is then 1 + v_i, v_i = g_i cov g_i^T / w_i^2 (g_i its row of the Jacobian), and its deviance
    z_i^2 / (1 + v_i) + ln(1 + v_i): a model whose extrapolation is as uncertain as its error is not
    charged the error twice, and an uncertain one pays the logarithm. Returns
    E = sqrt(sum_i r_i^2 / (1 + v_i) + w_i^2 ln(1 + v_i)): the plain E with v = 0; E 1 at the scatter.
    """
    c = train.candidate
    u = c.to_unit(np.asarray(theta, dtype=float))
    free = c.grown.free_mask(HELD) & (u > 1e-4) & (u < 1.0 - 1e-4)
    idx = np.flatnonzero(free)
    r, G = _unit_jacobian(test, u, idx)
    if idx.size == 0:
        return float(np.sqrt(np.sum(r**2)))
    _, J = _unit_jacobian(train, u, idx)
    # g cov g^T = |g J^+ W|^2 (J^+ the pseudo-inverse): the same, and never negative by rounding
    w2 = test.weights() ** 2
    v = np.sum((G @ np.linalg.pinv(J, rcond=1e-10) * train.weights()) ** 2, axis=1) / w2
    return float(np.sqrt(np.sum(r**2 / (1.0 + v) + w2 * np.log1p(v))))


def _rms(values) -> float:
    return float(np.sqrt(np.mean(np.square(list(values))))) if len(values) else float("nan")


def side_by_side(executor, fn, jobs: Sequence[tuple], sizes: Sequence[int]):
    """``fn(*job)`` of each job, read back in order: on the executor, the jobs of the largest `sizes` (the
    candidates with the most parameters, the longest fits) submitted first; here, one after the other."""
    if executor is None or len(jobs) < 2:
        return (fn(*j) for j in jobs)
    futures = {i: executor.submit(fn, *jobs[i]) for i in sorted(range(len(jobs)), key=lambda i: -sizes[i])}
    return (futures[i].result() for i in range(len(jobs)))


def _fit_and_hold_out(c: Candidate, runs: Sequence[RunEnvelope], starts: Sequence[np.ndarray], max_nfev: int,
                      folds: dict[str, list[int]], predictive: bool, objective) -> tuple[Fit, dict, float]:
    """One candidate's fit on all runs (the lowest E from `starts`) and its held-out E per fold, and the seconds
    they took: the part of `score_candidates` that is the candidate's alone."""
    t0 = time.perf_counter()
    obj = objective(c, runs)
    fits = [obj.fit(start, starts=1 if c.name == "baseline" else 3, max_nfev=max_nfev, refresh=1) for start in starts]
    full = min(fits, key=lambda f: f.E)
    per = _held_out(obj.at(full.theta), full, max_nfev, folds, predictive) if folds else {}
    return full, per, time.perf_counter() - t0


def score_candidates(cands: Sequence[Candidate], runs: Sequence[RunEnvelope], theta_base, *,
                     max_nfev: int = 40, log=None, baseline: Scored | None = None,
                     starts: dict[str, Sequence[np.ndarray]] | None = None, objective=Objective,
                     folds: dict[str, list[int]] | None = None, predictive: bool = False,
                     executor=None) -> list[Scored]:
    """Fit every candidate on all runs, then score it on held-out folds (see the module notes).

    The baseline is scored first (added if `cands` lacks it and `baseline` is not given): the
    other scores refer to it. Each fit refreshes the runs' sweep transient at its optimum,
    and the folds keep the full fit's. starts : candidate name -> physical starts (joint
    parameters and the values of its first effects, e.g. a single effect's fit for a pair);
    the fit from each is made and the lowest E on all runs kept (default: theta_base). objective : the
    objective of a candidate on the runs (the sweeps' `Objective`; ring-downs: `decays.DecayObjective`);
    folds : the held-out folds (default: the sweeps' levels, directions and rates, `_folds`); predictive :
    each fold's E as its predictive deviance (`predictive_E`; an objective with ``weights``). executor : a
    `concurrent.futures.Executor` the candidates are fitted on, side by side (each candidate's fit is its own,
    so the scores are those of the serial run, None).
    """
    cands = sorted(cands, key=lambda c: c.name != "baseline")
    if baseline is None and (not cands or cands[0].name != "baseline"):
        cands = [Candidate("baseline", cands[0].space, cands[0].m), *cands]
    folds = _folds(runs) if folds is None else folds
    out, base_per = [], (baseline.held_out if baseline is not None else {})
    base_score = baseline.score if baseline is not None else None
    jobs = [(c, runs, (starts or {}).get(c.name, [theta_base]), max_nfev, folds, predictive, objective)
            for c in cands]
    done = side_by_side(executor, _fit_and_hold_out, jobs, [len(c.names) for c in cands])
    for c, (full, per, seconds) in zip(cands, done):
        if c.name == "baseline":
            base_per = per
            s = _rms(per.values()) if per else full.E
            base_score = s
        elif not folds:
            s = full.E
        elif len(per) == len(folds):
            s = _rms(per.values())
        else:  # judged on a subset of the folds: relative to the baseline on the same subset
            s = base_score * _rms(per.values()) / _rms([base_per[k] for k in per])
        s *= 1.0 + PENALTY_PER_PARAM * (len(c.names) - 6)
        out.append(Scored(c.name, full, s, per, seconds))
        if log:
            log(f"{c.name}: E on all runs {full.E:.2f}, held-out score {s:.2f} ({seconds:.1f} s)")
    return out
