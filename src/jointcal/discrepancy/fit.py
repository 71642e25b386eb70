"""Fit the baseline or a candidate model to the measured envelopes through the fast model.

Objective: the validation error E (`jointcal.validate.envelope_error`) computed with the
steady-state envelope model (`jointcal.models.steady_state`) instead of a time
simulation: per frame the magnitude error (dB) and phase error (deg) of the model's
transmissibility against the measured one, each over the repeat scatter of its bin,
every run weighted equally; E^2 = (E_mag^2 + E_phase^2) / 2. A steady-state model seen
through a sweep lags: to first order in the sweep rate r (Hz/s, signed) a quasi-steady
sweep shows T(f - r tau_g(f)), tau_g = -d arg T / d omega the group delay, which is
applied to the model (the fits then do not mistake the sweep's lag for an effect).

Parameters live in a unit cube: the calibration's space (`jointcal.calibrate.space`)
grown by the effect's own parameters (`ParamSpace.grow` with `library.EffectParam`'s
bounds and scaling). Bounded least squares (`scipy.optimize.least_squares`) from
the baseline calibration and from each of the effect's start values; the Jacobian is one
batched call of the fast model over the perturbed parameter sets.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..calibrate.space import PARAMS, ParamSpace
from ..models import IwanParams, MinistackModel, steady_state
from .data import RunEnvelope
from .library import EFFECTS, apply_effect

__all__ = ["Candidate", "Fit", "candidate", "model_at", "fit_candidate", "envelope_E", "predict"]


@dataclass(frozen=True)
class Candidate:
    """A model to fit: the baseline joint space grown by an effect's parameters ('baseline': none)."""

    name: str
    space: ParamSpace
    m: float

    @property
    def effect_params(self):
        return () if self.name == "baseline" else EFFECTS[self.name].params

    @cached_property
    def grown(self) -> ParamSpace:
        """The calibration's space with the effect's parameters appended (`ParamSpace.grow`)."""
        e = self.effect_params
        return self.space.grow([p.name for p in e], [p.lo for p in e], [p.hi for p in e], [p.log for p in e])

    @property
    def names(self) -> tuple[str, ...]:
        return self.grown.names

    def to_physical(self, u: NDArray) -> NDArray:
        """Unit cube (..., n) -> physical values (..., n)."""
        return self.grown.to_physical(u)

    def to_unit(self, theta: NDArray) -> NDArray:
        """Physical values (..., n) -> unit cube (..., n)."""
        return self.grown.to_unit(theta)


def candidate(name: str, space: ParamSpace, m: float) -> Candidate:
    if name != "baseline" and name not in EFFECTS:
        raise ValueError(f"unknown candidate {name!r}; choose baseline or one of {', '.join(EFFECTS)}.")
    return Candidate(name, space, m)


def model_at(c: Candidate, theta: NDArray, row: Mapping) -> MinistackModel:
    """The model of parameter sets theta (n,) or (P, n) for the run of `row` (batched fields (P, 1))."""
    th = np.asarray(theta, dtype=float)
    col = (lambda i: th[..., i:i + 1]) if th.ndim == 2 else (lambda i: float(th[i]))
    base = MinistackModel(m=c.m, k=col(4), zeta_v=col(5), iwan=IwanParams(col(0), col(1), col(2), col(3)))
    values = {p.name: col(6 + i) for i, p in enumerate(c.effect_params)}
    return apply_effect(base, c.name, values, row)


def predict(c: Candidate, theta: NDArray, run: RunEnvelope) -> NDArray[np.complex128]:
    """Model transmissibility at the run's frames as the sweep shows it (first-order lag), (P, n) or (n,)."""
    model = model_at(c, theta, run.row)
    direction = "up" if run.rate >= 0 else "down"
    T = steady_state(model, run.f_hz, run.base_g, direction=direction).transmissibility
    order = np.argsort(run.f_hz)
    f = run.f_hz[order]
    Ts = T[..., order]
    ph = np.unwrap(np.angle(Ts), axis=-1)
    dT = np.gradient(Ts, f, axis=-1)
    tau = -np.gradient(ph, 2 * np.pi * f, axis=-1)  # group delay, s
    lagged = Ts - run.rate * tau * dT  # T(f - r tau_g), first order
    out = np.empty_like(T)
    out[..., order] = lagged
    return out


def _run_residual(c: Candidate, theta: NDArray, run: RunEnvelope, n_runs: int) -> NDArray:
    d = predict(c, theta, run) / run.T
    w = 1.0 / np.sqrt(2.0 * run.f_hz.size * n_runs)
    dm = 20 * np.log10(np.abs(d)) / run.sigma_db
    dp = np.degrees(np.angle(d)) / run.sigma_deg
    return np.concatenate([dm, dp], axis=-1) * w


def residuals(c: Candidate, theta: NDArray, runs: Sequence[RunEnvelope]) -> NDArray:
    """Residual vector whose sum of squares is E^2 (theta (n,) -> (m,), (P, n) -> (P, m))."""
    with np.errstate(all="ignore"):
        r = np.concatenate([_run_residual(c, theta, run, len(runs)) for run in runs], axis=-1)
    return np.where(np.isfinite(r), r, 1e3)


def envelope_E(c: Candidate, theta: NDArray, runs: Sequence[RunEnvelope]) -> float:
    """E of the fast model at theta over `runs` (the validation's definition, steady state + lag)."""
    return float(np.sqrt(np.sum(residuals(c, theta, runs) ** 2)))


@dataclass(frozen=True)
class Fit:
    """A fitted candidate: physical parameters, E over the fitted runs, and an approximate covariance."""

    name: str
    theta: NDArray[np.float64]
    E: float
    cov_unit: NDArray[np.float64]
    n_eval: int


def fit_candidate(c: Candidate, runs: Sequence[RunEnvelope], theta0: NDArray, *, starts: int = 3,
                  max_nfev: int = 60, free_joint: bool = True) -> Fit:
    """Bounded least squares of E^2 over the candidate's unit cube, from theta0 and effect start values.

    theta0 : (6,) or (n,) physical start (the baseline's joint parameters; effect values
    default to their `start`). starts : effect starts tried (the `start` value and evenly
    spread points of the unit interval). free_joint : False holds the joint parameters.
    """
    n = len(c.names)
    th0 = np.empty(n)
    th0[:6] = np.asarray(theta0, dtype=float)[:6]
    for i, p in enumerate(c.effect_params):
        th0[6 + i] = theta0[6 + i] if len(theta0) > 6 + i else p.start
    u0 = np.clip(c.to_unit(th0), 1e-6, 1 - 1e-6)
    free = np.ones(n, bool) if free_joint else np.r_[np.zeros(6, bool), np.ones(n - 6, bool)]
    # beta is barely identifiable from envelopes and sits on its floor in most joints: held
    free[PARAMS.index("beta")] = False
    inits = [u0]
    if n > 6:
        for s in np.linspace(0.15, 0.85, max(0, starts - 1)):
            u = u0.copy()
            u[6:] = s
            inits.append(u)
    h = 1e-5
    count = [0]

    def full(v):
        u = u0.copy()
        u[free] = v
        return u

    def fun(v):
        count[0] += 1
        return residuals(c, c.to_physical(full(v)), runs)

    def jac(v):
        u = full(v)
        idx = np.flatnonzero(free)
        U = np.repeat(u[None], idx.size, axis=0)
        step = np.where(u[idx] + h <= 1, h, -h)
        U[np.arange(idx.size), idx] += step
        count[0] += 1
        R = residuals(c, c.to_physical(U), runs)
        return ((R - fun(v)) / step[:, None]).T

    best = None
    for u in inits:
        res = least_squares(fun, u[free], jac=jac, bounds=(0.0, 1.0), method="trf", max_nfev=max_nfev,
                            x_scale="jac")
        if best is None or res.cost < best.cost:
            best = res
    # Gauss-Newton covariance in the unit cube: the residuals are weighted by 1/sqrt(n_res) against
    # unit-variance frames, so the information is J^T J n_res (frames taken as independent: the
    # intervals are approximate), inflated by E^2 when the fit is worse than the scatter
    J = best.jac
    try:
        cov_f = np.linalg.pinv(J.T @ J * J.shape[0]) * max(2 * best.cost, 1.0)
    except np.linalg.LinAlgError:
        cov_f = np.full((J.shape[1], J.shape[1]), np.nan)
    cov = np.zeros((n, n))
    cov[np.ix_(free, free)] = cov_f
    u = full(best.x)
    return Fit(c.name, c.to_physical(u), float(np.sqrt(2 * best.cost)), cov, count[0])
