"""Act: recalibrate the chosen model -- DEAP GA over the grown space, polish, emcee posterior.

1. GA (`jointcal.calibrate.run_ga`, DEAP) over the candidate's unit cube (the calibration's
   space grown by the effect's parameters, `ParamSpace.grow`); objective E^2 of the fast
   model over all runs (`fit.residuals`, one batched call per generation; the sweep
   transient at the best least-squares start, refreshed at the polished optimum). The seeded
   initial population holds the candidate's least-squares fits (from the calibration's
   optimum and from the GA's other Fs valleys), so the GA explores around and between them.
2. Polish: bounded least squares from the GA's best (`fit.fit_candidate`).
3. Posterior: emcee (`jointcal.posterior.sampler.run_chain`), uniform prior on the unit
   cube, log L = -N E^2 / (2 T) with N the number of residuals (each frame's magnitude and
   phase over the repeat scatter of its bin) and T = max(E_opt^2, 1): a model that misses by
   more than the scatter gets intervals as wide as its misfit (the Gauss-Newton convention
   of `fit`). Envelope frames overlap in time, so they are not independent and the
   intervals are approximate. Walkers start in a small ball around the polished optimum;
   the chain runs until 50 autocorrelation times or `steps`; the 90% intervals are the
   5-95% quantiles of the chain's second half.

beta is held (GA and chain) at the value of the best least-squares fit, as those fits hold
it: the envelopes barely constrain it, and left free it drags the Fs-KT-k split into other
valleys of equal E. Its reported interval is that single value.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..calibrate.ga import GAOptions, run_ga
from ..calibrate.space import PARAMS
from ..posterior.sampler import run_chain
from .data import RunEnvelope
from .fit import Candidate, Fit, fit_candidate, residuals, with_transient

__all__ = ["Recalibration", "recalibrate"]


@dataclass(frozen=True)
class Recalibration:
    """The recalibrated model: polished optimum, GA record and posterior summary.

    fit : the polished least-squares `Fit` (theta in physical units, E over all runs);
    ga_best_E : E of the GA's best individual; ga_generations : generations run;
    q05, q50, q95 : posterior quantiles of each parameter (physical units, `names` order);
    steps, walkers, tau_max, converged : the chain's length, its walkers, its largest autocorrelation time
    (steps) and whether the 50-tau rule was met; acceptance : mean acceptance fraction.
    """

    names: tuple[str, ...]
    fit: Fit
    ga_best_E: float
    ga_generations: int
    q05: NDArray[np.float64]
    q50: NDArray[np.float64]
    q95: NDArray[np.float64]
    steps: int
    walkers: int
    tau_max: float
    converged: bool
    acceptance: float

    def interval(self, i: int) -> list[float]:
        """90% credible interval of parameter i, physical units."""
        return [float(self.q05[i]), float(self.q95[i])]


def recalibrate(c: Candidate, runs: Sequence[RunEnvelope], starts: Sequence[Fit], *, seed: int = 2017,
                population: int = 48, generations: int = 30, walkers: int = 32, steps: int = 800,
                max_nfev: int = 50) -> Recalibration:
    """GA + polish + emcee of candidate `c` on the runs' envelopes (see the module notes).

    starts : least-squares fits of `c` (e.g. from the calibration's optimum and other valleys)
    seeded into the GA's initial population. seed : seeds the GA and the sampler.
    """
    space = c.grown
    n = space.ndim
    # beta is held where the least-squares fits hold it (see the module notes)
    free = np.ones(n, bool)
    free[PARAMS.index("beta")] = False
    held = [np.clip(c.to_unit(min(starts, key=lambda f: f.E).theta), 0.0, 1.0)]
    runs = with_transient(c, min(starts, key=lambda f: f.E).theta, runs)  # the sweep transient at the best start

    def full(V: NDArray) -> NDArray:
        U = np.repeat(held[0][None], len(V), axis=0)
        U[:, free] = V
        return U

    def batch(V: NDArray) -> NDArray:
        return np.sum(residuals(c, c.to_physical(full(np.atleast_2d(V))), runs) ** 2, axis=-1)

    init = np.array([np.clip(c.to_unit(f.theta), 0.0, 1.0)[free] for f in starts]).reshape(-1, int(free.sum()))
    ga = run_ga(batch, int(free.sum()), GAOptions(population=population, offspring=population,
                                                   generations=generations, stall_generations=8, seed=seed), init=init)
    pol = fit_candidate(c, runs, c.to_physical(full(ga.best[None])[0]), starts=1, max_nfev=max_nfev, refresh=1)
    best = min([pol, *starts], key=lambda f: f.E)
    held[0] = np.clip(c.to_unit(best.theta), 0.0, 1.0)  # the chain holds beta at the chosen fit's value
    runs = with_transient(c, best.theta, runs)
    n_res = residuals(c, best.theta, runs).size
    temp = max(best.E**2, 1.0)

    def log_prob(V: NDArray) -> NDArray:
        inside = np.all((V >= 0.0) & (V <= 1.0), axis=1)
        out = np.full(V.shape[0], -np.inf)
        if inside.any():
            out[inside] = -0.5 * n_res * batch(V[inside]) / temp
        return out

    u0 = np.clip(held[0][free], 1e-4, 1 - 1e-4)
    # the Gauss-Newton width, within [0.003, 0.01] of the unit cube: a flat direction must not
    # start as a point, or the ensemble explores it too slowly
    sd = np.sqrt(np.clip(np.diag(best.cov_unit)[free], 9e-6, 1e-4))
    rng = np.random.default_rng(seed)
    x0 = np.clip(u0 + rng.standard_normal((walkers, u0.size)) * sd, 0.0, 1.0)
    ch = run_chain(log_prob, x0, seed=seed, max_steps=steps, chunk=max(50, steps // 4), stop_projected=0.0)
    keep = ch.chain[len(ch.chain) // 2:].reshape(-1, u0.size)
    phys = c.to_physical(full(keep))
    q05, q50, q95 = np.quantile(phys, [0.05, 0.5, 0.95], axis=0)
    return Recalibration(space.names, best, float(np.sqrt(ga.best_value)), int(ga.generations), q05, q50, q95,
                         int(len(ch.chain)), int(walkers), float(np.max(ch.tau)), bool(ch.converged),
                         float(np.mean(ch.acceptance)))
