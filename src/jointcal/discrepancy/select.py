"""Decide: refit the baseline and every library candidate, score them on runs they did not fit, name one.

Held-out score. For each tested level L (with at least two levels), every model is refit
on the runs of the other levels (warm started from its fit on all runs) and its fast-model
E is taken on the runs of level L; likewise each sweep direction is predicted from the
runs of the other (up and down runs interleave in the sequence, so a drift with the run
sequence is judged on runs between fitted ones). The score is the RMS of those E over the
folds. A model that changes with the run sequence (`Effect.sequence_dependent`) is not
judged on a fold whose held-out runs lie mostly outside the fitted runs' span of the
sequence (holding out the 1 g level removes the start of a Table 3.1 series: the drift would
be extrapolated backward past every fitted run); its score is the baseline's over all folds
times its RMS over ratio the baseline's on the folds it is judged on. The
held-out runs penalise flexibility (an extra parameter that only absorbs the fitted
runs' noise predicts the unseen level no better), and a further complexity penalty of
`PENALTY_PER_PARAM` (relative, per extra parameter) is applied to the score.

Decision rule (scores S; S_b the baseline's, S_1 <= S_2 the two best candidates'):

* ``none``        when S_b <= `NONE_E` (the baseline already predicts unseen levels within
                  1.5x the measured repeat scatter) -- unless the best candidate predicts
                  them far better still, S_1 <= `WITHIN_SCATTER` S_b, and decisively
                  (S_1 <= MARGIN S_2): then the "scatter" itself is systematic (repeats
                  that drift with the sequence inflate the repeat scatter they are judged
                  by) and the candidate is named with confidence 'medium';
* the best name   when it closes at least `CLOSE_FRACTION` of the baseline's excess gap,
                  S_b - S_1 >= CLOSE_FRACTION (S_b - 1), AND beats the runner-up decisively,
                  S_1 <= `MARGIN` S_2; confidence 'high' if it also reaches S_1 <= 2 (the
                  gap closed to about the scatter), else 'medium';
* ``unexplained`` otherwise: the gap is real and no single library effect closes it (or two
                  close it equally well); the ranked candidates and the fingerprints that
                  disagree with each are reported.

A fingerprint no library effect can leave (`fingerprints.outside_library`: a dominant even
harmonic) caps the decision: the best name is kept only if it closes the gap to about the
scatter (S_1 <= 2), and then with confidence 'medium'; otherwise ``unexplained``.
"""
from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .data import RunEnvelope
from .fit import Candidate, Fit, envelope_E, fit_candidate
from .library import EFFECTS

__all__ = ["NONE_E", "CLOSE_FRACTION", "MARGIN", "PENALTY_PER_PARAM", "WITHIN_SCATTER", "Scored", "score_candidates", "decide"]

NONE_E = 1.5
CLOSE_FRACTION = 0.6
MARGIN = 0.7
PENALTY_PER_PARAM = 0.02
WITHIN_SCATTER = 0.5


@dataclass
class Scored:
    """A candidate's full fit, its held-out score and per-level E, and the time it took."""

    name: str
    fit: Fit
    score: float
    held_out: dict = field(default_factory=dict)
    seconds: float = 0.0


def _folds(runs: Sequence[RunEnvelope]) -> dict[str, list[int]]:
    """Held-out folds: each level, and each sweep direction predicted from the other.

    Levels test the amplitude dependence (a model that only absorbs the fitted levels predicts
    an unseen one no better); directions interleave in the run sequence (up, down, up, ...),
    so a drift with the sequence is judged on runs between fitted ones, and a sweep effect on
    the branch it was not fitted on."""
    levels = [float(r.row["level_g"]) for r in runs]
    folds = {f"{L:g} g": [i for i, v in enumerate(levels) if v == L] for L in sorted(set(levels))}
    if len(folds) < 2:
        return {}
    dirs = [str(r.row.get("direction", "")) for r in runs]
    if len(set(dirs)) > 1:
        folds.update({d: [i for i, v in enumerate(dirs) if v == d] for d in sorted(set(dirs))})
    return folds


def _extrapolates_sequence(runs: Sequence[RunEnvelope], idx: list[int]) -> bool:
    """True when most held-out runs lie outside the training runs' span of the run sequence."""
    seq = np.array([float(r.row.get("sequence", i)) for i, r in enumerate(runs)])
    train = np.delete(seq, idx)
    if train.size == 0:
        return True
    outside = (seq[idx] < train.min()) | (seq[idx] > train.max())
    return bool(outside.mean() > 0.5)


def _held_out(c: Candidate, runs: Sequence[RunEnvelope], full: Fit, max_nfev: int,
              folds: dict[str, list[int]]) -> dict[str, float]:
    """E of the candidate refit without each fold, on that fold (folds it cannot be judged on left out)."""
    per = {}
    seq_dep = c.name != "baseline" and EFFECTS[c.name].sequence_dependent
    for name, idx in folds.items():
        if seq_dep and _extrapolates_sequence(runs, idx):
            continue
        test = [runs[i] for i in idx]
        train = [r for i, r in enumerate(runs) if i not in set(idx)]
        f = fit_candidate(c, train, full.theta, starts=1, max_nfev=max_nfev)
        per[name] = envelope_E(c, f.theta, test)
    return per


def _rms(values) -> float:
    return float(np.sqrt(np.mean(np.square(list(values))))) if len(values) else float("nan")


def score_candidates(cands: Sequence[Candidate], runs: Sequence[RunEnvelope], theta_base, *,
                     max_nfev: int = 40, log=None) -> list[Scored]:
    """Fit every candidate on all runs, then score it on held-out folds (see the module notes).
    The baseline is scored first (added if `cands` lacks it): the other scores refer to it."""
    cands = sorted(cands, key=lambda c: c.name != "baseline")
    if cands[0].name != "baseline":
        cands = [Candidate("baseline", cands[0].space, cands[0].m), *cands]
    folds = _folds(runs)
    out, base_per = [], {}
    for c in cands:
        t0 = time.perf_counter()
        full = fit_candidate(c, runs, theta_base, starts=1 if c.name == "baseline" else 3, max_nfev=max_nfev)
        per = _held_out(c, runs, full, max_nfev, folds) if folds else {}
        if c.name == "baseline":
            base_per = per
            s = _rms(per.values()) if per else full.E
        elif not folds:
            s = full.E
        elif len(per) == len(folds):
            s = _rms(per.values())
        else:  # judged on a subset of the folds: relative to the baseline on the same subset
            s = _rms(base_per.values()) * _rms(per.values()) / _rms([base_per[k] for k in per])
        s *= 1.0 + PENALTY_PER_PARAM * (len(c.names) - 6)
        out.append(Scored(c.name, full, s, per, time.perf_counter() - t0))
        if log:
            log(f"{c.name}: E on all runs {full.E:.2f}, held-out score {s:.2f} ({time.perf_counter() - t0:.1f} s)")
    return out


def decide(scored: Sequence[Scored], outside: str | None = None) -> tuple[str, str, list[Scored]]:
    """(effect or 'none'/'unexplained', confidence, candidates ranked by score) by the module's rule.

    outside : a fingerprint no library effect leaves (`fingerprints.outside_library`), or None.
    """
    base = next(s for s in scored if s.name == "baseline")
    ranked = sorted((s for s in scored if s.name != "baseline"), key=lambda s: s.score)
    s1 = ranked[0].score if ranked else np.inf
    s2 = ranked[1].score if len(ranked) > 1 else np.inf
    if base.score <= NONE_E:
        if s1 <= WITHIN_SCATTER * base.score and s1 <= MARGIN * s2 and not outside:
            return ranked[0].name, "medium", ranked
        return "none", "high" if (not ranked or s1 > 0.8 * base.score) else "medium", ranked
    if not ranked:
        return "unexplained", "low", ranked
    closes = base.score - s1 >= CLOSE_FRACTION * (base.score - 1.0)
    decisive = s1 <= MARGIN * s2
    if closes and decisive and outside and s1 > 2.0:
        return "unexplained", "low", ranked
    if closes and decisive:
        return ranked[0].name, "high" if (s1 <= 2.0 and not outside) else "medium", ranked
    return "unexplained", "low", ranked
