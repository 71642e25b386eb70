"""One assembly's calibration: GA on eq. 3.9, a least-squares polish, and the output tables.

The GA (`jointcal.calibrate.ga`) explores the bounds and finds the basins; it does not
resolve the optimum to the 0.01% level of the frequency residuals in 100 generations
(measured on Table 3.2 campaigns: the GA's best objectives of 5 seeds spread by
5-1000%), and a seed can end in a local minimum where macroslip starts at a measured
amplitude (a kink of the model; objective 3x the global one). So the GA's evaluations
seed a multi-start polish: the best evaluated individuals that lie at least
``min_distance`` apart in the unit cube (``n_polish`` of them, best first), and the best
individual of every macroslip regime (number of measured amplitudes beyond phi_max), are
each refined by bounded least squares (scipy `least_squares`, trust-region reflective, in the
GA's unit cube, on the residual vector whose squared norm is eq. 3.9), and the lowest
result wins. `ga_best.json` reports both the GA's own best (``objective_ga``) and the
polished one (``objective``).

**Points with their own standard errors** (a campaign of ring-downs alone: every point a window whose
read-out gives its standard errors, `ModalData.sigma`; or of ring-downs and dwells alone, a level of dwells'
phase resonance then at the noise floors, 1e-4 in f and 0.01 in zeta: on the real UNESP beam's five dwells and
their decays, 2026-11-27, the validation's E 78.2 with eq. 3.9's polish, 11.7 on this scale, E_f 138 -> 19):
the GA still searches on eq. 3.9, but the polish
refines on the residuals over those standard errors, the likelihood's scale and the validation's
(`jointcal.validate.decay`: each window judged on its own standard error),

    r = sqrt(w_i / (2 N)) ((f_i - f~(q_i)) / f_i / s_f,i , (zeta_i - zeta~(q_i)) / zeta_i / s_zeta,i),

N = sum w the read-outs, so |r|^2 is the validation's E^2 of the backbone (each run's mean over its windows
of (r_f^2 + r_zeta^2) / 2, averaged over runs; `E_backbone` in ga_best.json). Eq. 3.9's eta weighs a relative
f error of 1e-4 against a zeta error of 1e-2 alike, so its optimum gives away f where the windows resolve it
to 7e-5 (beam, seed 1, of tests/_support/decay_campaign.py, 'none': the eq. 3.9 polish E 2.89 = E_f 4.04,
E_zeta 0.61 in the validation, the truth 0.81). Among the polished optima whose -2 ln L = 2 N E_backbone^2
lies within `TIE` of the lowest, the one with the fewest windows that reach macroslip (their start's
amplitude `ModalData.q_top` >= phi_max) wins, then the lowest: the harmonic balance's steady backbone is not
what a decay through the macroslip knee reads, so a knee within the windows must earn its place by a
likelihood-ratio test at 5% (3.84, chi^2 of one degree of freedom: the one window a free knee fits). On the
beam's seed 1 a knee put at the top window fit the backbone to E 0.851 against the smooth 0.856, and the
validation's time simulation read that window -8.7 sigma in f and +10.5 in zeta (E 2.41 against 0.82).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.optimize import least_squares

from .data import ModalData
from .ga import GAOptions, GAResult, run_ga
from .objective import MODELS, objective, predict
from .settings import CalibrateSettings
from .space import ParamSpace

__all__ = ["Calibration", "calibrate", "least_squares_polish", "model_curves", "polish", "polish_starts", "search",
           "pick_polished", "TIE"]

TIE = 3.84  # -2 ln L within this of the lowest: chi^2(1) at 95%, optima not told apart (`pick_polished`)


@dataclass
class Calibration:
    """Outcome of `calibrate`: ``best`` (JSON-ready dict for ga_best.json), ``ga``
    (GAResult), and the tables ``history``, ``logbook`` and ``curves``."""

    best: dict[str, Any]
    ga: GAResult
    history: pd.DataFrame
    logbook: pd.DataFrame
    curves: pd.DataFrame


def _residuals(theta: NDArray[np.float64], data: ModalData, s: CalibrateSettings,
               space: ParamSpace) -> NDArray[np.float64]:
    """Residual vectors whose squared norms are eq. 3.9 (points with their own standard errors: E^2 of the
    backbone, module notes), shape (P, 2N), for parameters theta (P, n) of `space` (`s.space`, built once by the
    caller: the property makes a new, validated space at each access)."""
    f_m, z_m = predict(space.joint(np.atleast_2d(theta)), data.q, m=s.m, model=s.model, viscous=s.viscous)
    n = data.q.size
    if data.sigma is not None:  # each point on its own standard errors: |r|^2 the validation's E^2 (module notes)
        a = np.sqrt(data.w / (2.0 * data.n_readouts))
        return np.concatenate([a * (data.f - f_m) / data.f / data.sigma[0],
                               a * (data.zeta - z_m) / data.zeta / data.sigma[1]], axis=1)
    if data.weight is not None:  # read-outs of many points: each residual times the square root of its weight
        w, n = data.w, data.n_readouts
        return np.concatenate([np.sqrt(s.eta * w / n) * (data.f - f_m) / data.f,
                               np.sqrt((1.0 - s.eta) * w / n) * (data.zeta - z_m) / data.zeta], axis=1)
    return np.concatenate([np.sqrt(s.eta / n) * (data.f - f_m) / data.f,
                           np.sqrt((1.0 - s.eta) / n) * (data.zeta - z_m) / data.zeta], axis=1)


def polish(u0: NDArray[np.float64], data: ModalData, s: CalibrateSettings) -> NDArray[np.float64]:
    """Refine a unit-cube point by bounded least squares on `_residuals` (`least_squares_polish`)."""
    space = s.space  # once, not at each of the least squares' evaluations
    return least_squares_polish(u0, lambda U: _residuals(space.to_physical(U), data, s, space))


def least_squares_polish(u0: NDArray[np.float64],
                         residuals: Callable[[NDArray[np.float64]], NDArray[np.float64]]) -> NDArray[np.float64]:
    """Refine a unit-cube point of any space by bounded least squares.

    Parameters
    ----------
    u0 : ndarray, shape (n,)
        Start in the unit cube.
    residuals : callable
        Unit-cube points (P, n) -> residual vectors (P, m) whose squared norm is minimised.

    Returns
    -------
    ndarray, shape (n,)
        The refined point; `u0` if the refinement does not lower the squared norm. The
        Jacobian is a forward difference evaluated in one vectorised call (n + 1 rows).
    """
    def fun_many(U):
        with np.errstate(all="ignore"):
            r = residuals(U)
        return np.where(np.isfinite(r), r, 1e5)

    def jac(u, h=1e-7):
        steps = np.where(u + h <= 1.0, h, -h)
        r = fun_many(np.vstack([u, u + np.diag(steps)]))
        return ((r[1:] - r[0]) / steps[:, None]).T

    u0 = np.clip(np.asarray(u0, dtype=float), 0.0, 1.0)
    sol = least_squares(lambda u: fun_many(u[None])[0], u0, jac=jac, bounds=(0.0, 1.0), method="trf",
                        x_scale="jac", ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=1000)
    return sol.x if np.sum(sol.fun**2) < np.sum(fun_many(u0[None])[0] ** 2) else u0


def _distinct(genes: NDArray[np.float64], n: int, min_distance: float) -> list[NDArray[np.float64]]:
    """The first `n` rows of `genes` at least `min_distance` apart (max-norm), in order."""
    picked: list[NDArray[np.float64]] = []
    for g in genes:
        if len(picked) == n:
            break
        if all(np.max(np.abs(g - p)) >= min_distance for p in picked):
            picked.append(g)
    return picked


def polish_starts(history: NDArray[np.float64], regime: NDArray[np.int_] | None = None, n: int = 8,
                  min_distance: float = 0.02, scan: int = 20000) -> NDArray[np.float64]:
    """Distinct good starting points for the polish, from the GA's evaluations.

    Parameters
    ----------
    history : ndarray, shape (n_evals, 2 + n)
        `GAResult.history` (generation, objective, genes).
    regime : ndarray of int, shape (n_evals,), optional
        A label per evaluation (here: how many measured amplitudes lie at or beyond
        macroslip, q >= phi_max). The `n` best distinct evaluations of every label are
        starts too, so each branch of the piecewise model gets polished even when the GA
        converged on another.
    n : int
        Starts per group: the best evaluations at least `min_distance` apart.
    min_distance : float
        Smallest max-norm distance between starts of a group in the unit cube.
    scan : int
        Only the `scan` best evaluations are considered.

    Returns
    -------
    ndarray, shape (m, n)
        Genes of the starts; the GA's best first.
    """
    finite = np.isfinite(history[:, 1])
    order = np.argsort(np.where(finite, history[:, 1], np.inf), kind="stable")[:scan]
    genes = history[order, 2:]
    picked = _distinct(genes, n, min_distance)
    if regime is not None:
        labels = np.asarray(regime)[order]
        for label in np.unique(labels):
            picked += _distinct(genes[labels == label], n, min_distance)
    starts = np.asarray(picked).reshape(-1, history.shape[1] - 2)
    _, first = np.unique(starts, axis=0, return_index=True)
    return starts[np.sort(first)]


def pick_polished(chi2: NDArray[np.float64], beyond: NDArray[np.int_], tie: float = TIE) -> int:
    """Which polished optimum wins when the points carry their own standard errors.

    Parameters
    ----------
    chi2 : ndarray, shape (k,)
        -2 ln L of each optimum (the squared norm of the residuals over the standard errors, times 2 N).
    beyond : ndarray of int, shape (k,)
        Windows that reach each optimum's macroslip onset (their start's amplitude >= phi_max).
    tie : float
        Optima within this of the lowest `chi2` are not told apart by the data.

    Returns
    -------
    int
        Among the tied, the one with the fewest amplitudes in macroslip, then the lowest `chi2`.
    """
    chi2, beyond = np.asarray(chi2, float), np.asarray(beyond)
    tied = np.isfinite(chi2) & (chi2 <= np.nanmin(chi2) + tie)
    return int(np.lexsort((chi2, np.where(tied, beyond, np.iinfo(np.int64).max)))[0])


def model_curves(theta: NDArray[np.float64], q_range: tuple[float, float], s: CalibrateSettings) -> pd.DataFrame:
    """Both models' f (Hz) and zeta on a log grid of amplitudes (in), for theta (n,) of `s.space`.

    The grid spans ``q_range`` widened by ``s.curve_widen`` on each side, with
    ``s.curve_points`` points; columns q_in, f_hz, zeta, model.
    """
    q = np.geomspace(q_range[0] / s.curve_widen, q_range[1] * s.curve_widen, s.curve_points)
    parts = []
    for name in MODELS:
        f, z = predict(s.space.joint(np.asarray(theta)[None]), q, m=s.m, model=name,  # type: ignore[arg-type]
                       viscous=s.viscous)
        parts.append(pd.DataFrame({"q_in": q, "f_hz": f[0], "zeta": z[0], "model": name}))
    return pd.concat(parts, ignore_index=True)


def search(batch: Callable[[NDArray[np.float64]], NDArray[np.float64]], space: ParamSpace, options: GAOptions, *,
           free: NDArray[np.bool_] | None = None, at: NDArray[np.float64] | None = None,
           init: NDArray[np.float64] | None = None, resume: dict[str, Any] | None = None,
           on_checkpoint: Callable[[dict[str, Any]], None] | None = None) -> GAResult:
    """The DEAP GA (`run_ga`) over the unit cube of any space: the joint's, or one grown by an effect's.

    Parameters
    ----------
    batch : callable
        Unit-cube points of the whole space (P, n) -> objective (P,), lower is better.
    space : ParamSpace
    options : GAOptions
    free : ndarray of bool, shape (n,), optional
        Columns the GA moves (default all); the others stay at `at`.
    at : ndarray, shape (n,), optional
        Unit-cube values of the held columns (needed when some are held).
    init : ndarray, shape (k, n_free), optional
        Seeded members of the initial population (free columns).
    resume, on_checkpoint :
        Passed to `run_ga`.

    Returns
    -------
    GAResult
        Genes of the free columns (`space.embed` gives the whole point).
    """
    if free is None or bool(np.all(free)):
        return run_ga(batch, space.ndim, options, init=init, resume=resume, on_checkpoint=on_checkpoint)
    return run_ga(lambda v: batch(space.embed(v, at, free)), int(np.sum(free)), options, init=init, resume=resume,
                  on_checkpoint=on_checkpoint)


def calibrate(data: ModalData, s: CalibrateSettings, *, resume: dict[str, Any] | None = None,
              on_checkpoint: Callable[[dict[str, Any]], None] | None = None) -> Calibration:
    """GA (DEAP) on eq. 3.9, then `polish`; the tables of the calibration stage.

    Parameters
    ----------
    data : ModalData
        One assembly's usable runs.
    s : CalibrateSettings
        Model, weight eta, bounds, GA options and seed.
    resume, on_checkpoint :
        Passed to `jointcal.calibrate.ga.run_ga`.

    Returns
    -------
    Calibration
    """
    space: ParamSpace = s.space

    def batch(u: NDArray[np.float64]) -> NDArray[np.float64]:
        return objective(space.joint(space.to_physical(u)), data.q, data.f, data.zeta, m=s.m, eta=s.eta, model=s.model,
                         viscous=s.viscous, valid=space.inside(u), weight=data.weight)

    ga = search(batch, space, s.ga, resume=resume, on_checkpoint=on_checkpoint)
    u_best = ga.best
    if s.n_polish > 0:
        phi_max = space.phi_max(space.to_physical(ga.evaluated))
        beyond = np.sum(data.q[None, :] >= phi_max[:, None], axis=1)  # measured amplitudes in macroslip
        starts = polish_starts(ga.history, beyond, s.n_polish)  # the GA's best comes first
        refined = np.array([polish(u, data, s) for u in starts])
        if data.sigma is None:
            u_best = refined[int(np.argmin(batch(refined)))]
        else:  # on the standard errors' scale, the knee's tie broken (module notes)
            th = space.to_physical(refined)
            chi2 = 2 * data.n_readouts * np.sum(_residuals(th, data, s, space) ** 2, axis=1)
            reach = data.q if data.q_top is None else data.q_top
            u_best = refined[pick_polished(chi2, np.sum(reach[None, :] >= space.phi_max(th)[:, None], axis=1))]
    theta = space.to_physical(u_best)
    value = float(batch(u_best[None])[0])
    n = data.q.size
    if data.weight is None:  # one point per run
        r = _residuals(theta, data, s, space)[0]
        rms = [float(np.sqrt(np.mean((r[:n] / np.sqrt(s.eta / n)) ** 2))) if s.eta > 0 else None,
               float(np.sqrt(np.mean((r[n:] / np.sqrt((1 - s.eta) / n)) ** 2))) if s.eta < 1 else None]
    else:  # the weighted rms over read-outs
        f_m, z_m = predict(space.joint(theta[None]), data.q, m=s.m, model=s.model, viscous=s.viscous)
        rms = [float(np.sqrt(np.sum(data.w * r**2) / data.n_readouts))
               for r in ((data.f - f_m[0]) / data.f, (data.zeta - z_m[0]) / data.zeta)]
    phi_max = float(space.phi_max(theta))
    best: dict[str, Any] = space.named(theta)
    best.update(
        objective=value, objective_ga=ga.best_value, n_polish=s.n_polish, seed=s.ga.seed,
        generations=ga.generations, stop_reason=ga.stop_reason, n_evaluations=int(len(ga.history)),
        model=s.model, viscous=s.viscous, damping=data.damping, eta=s.eta, m=s.m, assembly=data.assembly,
        n_runs=n if data.weight is None else len({r for ids in data.run_id for r in ids.split("+")}),
        q_min_in=float(data.q.min()), q_max_in=float(data.q.max()), phi_max_in=phi_max,
        f0_hz=float(np.sqrt(space.stuck_stiffness(theta) / s.m) / (2 * np.pi)),
        rms_rel_residual_f=rms[0] if s.eta > 0 else None,
        rms_rel_residual_zeta=rms[1] if s.eta < 1 else None,
    )
    if data.weight is not None:  # a ring-down's windows: points and read-outs are not runs
        best.update(n_points=n, n_readouts=data.n_readouts)
    if data.sigma is not None:  # polished on the windows' standard errors
        best.update(polish_scale="standard_error",
                    E_backbone=float(np.sqrt(np.sum(_residuals(theta, data, s, space)[0] ** 2))))
    history = pd.DataFrame(space.to_physical(ga.evaluated), columns=list(space.names))
    history.insert(0, "objective", ga.objectives)
    history.insert(0, "generation", ga.generation_of)
    logbook = pd.DataFrame(list(ga.logbook))[["gen", "nevals", "min", "median", "max", "best", "sigma"]]
    curves = model_curves(theta, (float(data.q.min()), float(data.q.max())), s)
    return Calibration(best=best, ga=ga, history=history, logbook=logbook, curves=curves)
