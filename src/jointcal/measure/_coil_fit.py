"""The swept-mode fit refitted with a voltage drive's coil, from the fit without it.

Private: `jointcal.measure.sweepfit.fit_swept_mode` calls `refit_with_coil` when given a coil.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ._sweep_problem import COIL_RANGE, NP, Problem

__all__ = ["refit_with_coil"]

CORNERS = (0.5,)  # start corners w_e / W0 of a coil fitted, beside the one A(w)'s slope implies


def refit_with_coil(prob: Problem, best, free: NDArray, coil) -> tuple[Problem, object, NDArray]:
    """(problem, solution, free set) of the fit with the coil: held at `coil` (w_e rad/s, g 1/s^2), or fitted
    (coil 'fit': from the corner A(w)'s slope implies and from `CORNERS`, the best kept) and kept where the
    information criterion asks for its two constants and the corner lies inside `COIL_RANGE`; else the fit
    without it, as given. The modal constant's slope is left out: the coil's roll-off was the slope's."""
    W0 = prob.ps.sig.W0
    mode, _ = prob.params(best.x, free)
    if coil != "fit":
        return _solve(prob, best, free, tuple(coil), held=True)
    a0, a1 = complex(mode[6], mode[7]), complex(mode[9], mode[10])
    # a coil's roll-off (w_e + i W0) / (w_e + i w) has A_1 / A_0 = -i W0 / (w_e + i W0)
    implied = float(np.clip((-1j * a0 / a1).real if abs(a1) > 0 else np.inf, 0.1, 1.9))
    fits = []
    for ratio in dict.fromkeys((implied, *CORNERS)):
        w_e = ratio * W0
        fits.append(_solve(prob, best, free, (w_e, 0.2 * mode[1] * (w_e**2 + W0**2) / w_e), held=False))
    with_coil, sol, free_c = min(fits, key=lambda f: f[1].cost)  # back-EMF damping started at a fifth of D
    n_eff = prob.n_res / 2
    rss, rss_c = (float(np.sum(x.fun[:prob.n_res] ** 2)) for x in (best, sol))
    corner = with_coil.params(sol.x, free_c)[0][12] / W0
    inside = COIL_RANGE[0] * 1.01 < corner < COIL_RANGE[1] / 1.01
    if inside and rss_c > 0 and n_eff * np.log(rss / rss_c) > 2 * np.log(n_eff):
        return with_coil, sol, free_c
    return prob, best, free


def _solve(prob: Problem, best, free: NDArray, start: tuple[float, float], held: bool):
    """The fit with the coil from `start` (held or fitted), its mode started where the fit without it was: the
    coil's steady back-EMF at W0 adds g W0^2 / (w_e^2 + W0^2) to Omega^2 and g w_e / (w_e^2 + W0^2) to D."""
    p = np.zeros(NP)
    p[free] = best.x
    W0 = prob.ps.sig.W0
    mode, _ = prob.params(best.x, free)
    w_e, g = start
    w2 = max(mode[0] - g * W0**2 / (w_e**2 + W0**2), 0.5 * mode[0])
    d = max(mode[1] - g * w_e / (w_e**2 + W0**2), 0.2 * mode[1])
    p[0], p[1] = 0.5 * np.log(w2 / W0**2), p[1] + np.log(d / mode[1])
    p[9:11] = 0.0
    with_coil = prob.with_coil(start, not held)
    free_c = np.union1d(free[~np.isin(free, (9, 10))], with_coil.free_all[with_coil.free_all >= 22])
    return with_coil, with_coil.solve(p[free_c], free_c, 100), free_c
