"""Decide: refit the baseline and every library candidate, score them on runs they did not fit, name one.

Held-out score. For each tested level L (with at least two levels), every model is refit
on the runs of the other levels (warm started from its fit on all runs) and its fast-model
E is taken on the runs of level L; the score is the RMS of those E over the levels. The
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


def _held_out(c: Candidate, runs: Sequence[RunEnvelope], full: Fit, max_nfev: int) -> tuple[float, dict]:
    levels = sorted({float(r.row["level_g"]) for r in runs})
    if len(levels) < 2:
        return full.E, {}
    per = {}
    for L in levels:
        train = [r for r in runs if float(r.row["level_g"]) != L]
        test = [r for r in runs if float(r.row["level_g"]) == L]
        f = fit_candidate(c, train, full.theta, starts=1, max_nfev=max_nfev)
        per[f"{L:g}"] = envelope_E(c, f.theta, test)
    return float(np.sqrt(np.mean(np.square(list(per.values()))))), per


def score_candidates(cands: Sequence[Candidate], runs: Sequence[RunEnvelope], theta_base, *,
                     max_nfev: int = 40, log=None) -> list[Scored]:
    """Fit every candidate on all runs, then score it on held-out levels (see the module notes)."""
    out = []
    for c in cands:
        t0 = time.perf_counter()
        full = fit_candidate(c, runs, theta_base, starts=1 if c.name == "baseline" else 3, max_nfev=max_nfev)
        s, per = _held_out(c, runs, full, max_nfev)
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
