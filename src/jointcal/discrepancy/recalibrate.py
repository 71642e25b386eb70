"""Act: recalibrate the chosen model with the calibration's GA and the posterior's sampler.

The candidate's space is the calibration's grown by the effect's parameters
(`ParamSpace.grow`); nothing here is specific to it:

1. GA: `jointcal.calibrate.search` (DEAP) over the grown unit cube, on E^2 of the fast
   model over all runs (`fit.residuals`, one batched call per generation; the sweep
   transient at the best least-squares start). The seeded initial population holds the
   candidate's least-squares fits (from the calibration's optimum and from the GA's other
   Fs valleys), so the GA explores around and between them.
2. Polish: bounded least squares from the GA's best (`fit.Objective.fit`, the transient
   refreshed at its optimum).
3. Posterior: `jointcal.posterior.ResidualPosterior` (uniform prior on the unit cube,
   log L = -N E^2 / (2 T), N the number of residuals -- each frame's magnitude and phase
   over the repeat scatter of its bin -- and T = max(E_opt^2, 1)) sampled by
   `jointcal.posterior.sample_ball` from a small ball around the polished optimum. Envelope
   frames overlap in time, so they are not independent and the intervals are approximate.
   The 90% intervals are the 5-95% quantiles of the chain's second half
   (`jointcal.posterior.draw_quantiles`).

beta is held (GA and chain) at the value of the best least-squares fit, as those fits hold
it: the envelopes barely constrain it, and left free it drags the Fs-KT-k split into other
valleys of equal E. Its reported interval is that single value.
"""
from __future__ import annotations

import pickle
import uuid
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
import pandas as pd

from ..calibrate.fit import pick_polished, search
from ..calibrate.ga import GAOptions
from ..posterior.likelihood import ResidualPosterior
from ..posterior.sampler import sample_ball
from ..posterior.summary import draw_quantiles
from .data import RunEnvelope
from .fit import HELD, Candidate, Fit, Objective

__all__ = ["Recalibration", "recalibrate"]


@dataclass(frozen=True)
class Recalibration:
    """The recalibrated model: polished optimum, GA record and posterior summary.

    fit : the polished least-squares `Fit` (theta in physical units, E over all runs);
    ga_best_E : E of the GA's best individual; ga_generations : generations run;
    quantiles : posterior q05, median, q95 of each parameter (physical units), indexed by name;
    steps, walkers, tau_max, converged : the chain's length, its walkers, its largest autocorrelation time
    (steps) and whether the 50-tau rule was met; acceptance : mean acceptance fraction.
    """

    fit: Fit
    ga_best_E: float
    ga_generations: int
    quantiles: pd.DataFrame
    steps: int
    walkers: int
    tau_max: float
    converged: bool
    acceptance: float

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.quantiles.index)

    def interval(self, name: str) -> list[float]:
        """90% credible interval of parameter `name`, physical units."""
        return [float(self.quantiles.at[name, "q05"]), float(self.quantiles.at[name, "q95"])]


_SENT: dict = {}  # in a pool's worker: the residual function it was sent last, by its key


def _residuals_sent(key: str, blob: bytes, theta: NDArray) -> NDArray:
    """A pool worker's half of a batch: the residual function pickled in `blob`, unpickled once per `key`."""
    if key not in _SENT:
        _SENT.clear()
        _SENT[key] = pickle.loads(blob)
    return _SENT[key](theta)


def _in_halves(residuals, executor, min_rows: int = 8):
    """`residuals` of a batch of parameter sets (P, n) -> (P, m) in two halves, the second on the executor (when
    given; the function pickled once, unpickled once per worker) while this process computes the first. Always
    in halves, pool or not: a set's residuals can differ at 1e-14 with the size of the batch they are computed in
    (vectorised kernels choose their paths by array size; a GA's best E moved in its last digit), so the same
    halves give the same numbers with or without the pool. Under 2 x min_rows sets: one call."""
    key, blob = (uuid.uuid4().hex, pickle.dumps(residuals)) if executor is not None else (None, None)

    def halves(theta):
        th = np.asarray(theta, dtype=float)
        if th.ndim < 2 or th.shape[0] < 2 * min_rows:
            return residuals(th)
        h = th.shape[0] // 2
        other = executor.submit(_residuals_sent, key, blob, th[h:]) if executor is not None else None
        first = residuals(th[:h])
        return np.concatenate([first, residuals(th[h:]) if other is None else other.result()])
    return halves


def _posterior(obj: Objective, at: Fit, temperature: float, executor=None) -> ResidualPosterior:
    """E^2 of the objective as a posterior over its free columns, the held ones at `at`'s values (each batch in
    halves over the executor, `_in_halves`)."""
    space = obj.candidate.grown
    return ResidualPosterior(space, _in_halves(obj.residuals, executor), obj.residuals(at.theta).size,
                             temperature, np.clip(space.to_unit(at.theta), 0.0, 1.0), space.free_mask(HELD))


def _chosen(fits: Sequence[Fit], c: Candidate, runs: Sequence, n_res: int) -> Fit:
    """The lowest E, or, for ring-down windows that know where they start (`DecayRun.q_top`), the calibration's
    rule (`jointcal.calibrate.fit.pick_polished`): among fits the data do not tell apart (-2 ln L = n_res E^2 / T,
    T as the chain's, within chi-square(1)'s 95% of the lowest), the one with the fewest windows reaching its
    macroslip onset: a knee placed on the top window fits the backbone there, not the ring-down read through it
    (a dwell's point counts at its own amplitude)."""
    tops = [getattr(r, "q_top", None) for r in runs]
    if all(t is None for t in tops):  # sweeps' frames, or windows of unknown length
        return min(fits, key=lambda f: f.E)
    tops = [r.q_in if t is None else t for r, t in zip(runs, tops)]  # a dwell's point: its own amplitude
    E = np.array([f.E for f in fits])
    chi2 = n_res * E**2 / max(float(np.min(E)) ** 2, 1.0)
    th = np.array([f.theta for f in fits])
    beyond = np.sum(np.concatenate(tops)[None, :] >= c.grown.phi_max(th)[:, None], axis=1)
    return fits[pick_polished(chi2, beyond)]


def recalibrate(c: Candidate, runs: Sequence[RunEnvelope], starts: Sequence[Fit], *, seed: int = 2017,
                population: int = 48, generations: int = 30, walkers: int = 32, steps: int = 800,
                max_nfev: int = 50, objective=Objective, executor=None) -> Recalibration:
    """GA + polish + emcee of candidate `c` on the runs' envelopes (see the module notes).

    starts : least-squares fits of `c` (e.g. from the calibration's optimum and other valleys)
    seeded into the GA's initial population. seed : seeds the GA and the sampler. objective : the
    candidate's objective on the runs (the sweeps' `Objective`; ring-downs: `decays.DecayObjective`). executor :
    a `concurrent.futures.Executor` that takes half of each batch of the GA and the chain (`_in_halves`: the same
    numbers as without).
    """
    first = min(starts, key=lambda f: f.E)
    obj = objective(c, runs).at(first.theta)  # the sweep transient at the best start
    lp = _posterior(obj, first, 1.0, executor)
    init = np.array([np.clip(c.to_unit(f.theta), 0.0, 1.0)[lp.free] for f in starts]).reshape(-1, lp.ndim)
    options = GAOptions(population=population, offspring=population, generations=generations, stall_generations=8,
                        seed=seed)
    ga = search(lp.misfit_unit, c.grown, options, free=lp.free, at=lp.at, init=init)
    pol = obj.fit(lp.physical(ga.best[None])[0], starts=1, max_nfev=max_nfev, refresh=1)
    best = _chosen([pol, *starts], c, runs, obj.residuals(pol.theta).size)
    # the chain holds beta at the chosen fit's value
    lp = _posterior(obj.at(best.theta), best, max(best.E**2, 1.0), executor)
    # the Gauss-Newton width, within [0.003, 0.01] of the unit cube: a flat direction must not
    # start as a point, or the ensemble explores it too slowly
    sd = np.sqrt(np.clip(np.diag(best.cov_unit)[lp.free], 9e-6, 1e-4))
    ch = sample_ball(lp, np.clip(lp.at[lp.free], 1e-4, 1 - 1e-4), sd, walkers=walkers, steps=steps, seed=seed)
    keep = ch.chain[len(ch.chain) // 2:].reshape(-1, lp.ndim)
    return Recalibration(best, float(np.sqrt(ga.best_value)), int(ga.generations),
                         draw_quantiles(lp.physical(keep), c.names), int(len(ch.chain)), int(walkers),
                         float(np.max(ch.tau)), bool(ch.converged), float(np.mean(ch.acceptance)))
