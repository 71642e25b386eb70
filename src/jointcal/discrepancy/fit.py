"""Fit the baseline or a candidate model to the measured envelopes through the fast model.

Objective: the validation error E (`jointcal.validate.envelope_error`) computed with the
swept envelope model (`jointcal.models.swept`) instead of a time simulation: per frame the magnitude error (dB) and phase error (deg) of the model's
transmissibility against the measured one, each over the repeat scatter of its bin,
every run weighted equally; E^2 = (E_mag^2 + E_phase^2) / 2. The model's envelope is the
one a sweep shows (`jointcal.models.swept`): the first-order quasi-steady envelope at
each frame (`quasi_steady`, cheap and batched over parameter sets) times the run's
transient factor, the slow flow integrated through the resonance over the first-order
envelope, both at a reference parameter set (`transient_factor`). One `Objective` (a candidate on
one assembly's runs, linearised at a parameter set) owns the residuals, E, the prediction and
the fit; a fit retakes the factor at its optimum and refits from there (`Objective.fit(refresh=...)`,
the factor retaken in one place, `Objective.at`): the factor changes
little with the parameters, and at convergence the fitted envelope is the integrated one.
So the fits do not mistake the sweep's lag, lower peak or ringing for an effect.

A candidate is the baseline, one library effect, or several joined by '+' (present
together). Parameters live in a unit cube: the calibration's space (`jointcal.calibrate.space`)
grown by the effects' own parameters (`ParamSpace.grow` with `jointcal.effects.EffectParam`'s
bounds and scaling). Bounded least squares (`scipy.optimize.least_squares`) from
the baseline calibration and from each of the effect's start values; the Jacobian is one
batched call of the fast model over the perturbed parameter sets.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ..calibrate.space import PARAMS, ParamSpace
from ..models import MinistackModel, swept_transmissibility
from ..models.swept import quasi_steady_runs
from ..validate.drive import delay_reference
from .data import RunEnvelope, run_zeta
from ..effects import EFFECTS, apply_effect, effects_of

__all__ = ["HELD", "Candidate", "Fit", "Objective", "candidate", "structure_scales", "model_at", "observed",
           "transient_factor", "refreshed_fit", "least_squares_fit"]

HELD = ("beta",)  # joint parameters the envelopes barely constrain: held at the start's value by every fit


@dataclass(frozen=True)
class Candidate:
    """A model to fit: the baseline joint space grown by its effects' parameters ('baseline': none;
    'a+b': effects a and b together)."""

    name: str
    space: ParamSpace
    m: float
    scales: tuple[tuple[str, float], ...] | None = None  # (K0, f0, q) of a structure other than the Ministack

    @property
    def effects(self) -> tuple[str, ...]:
        return effects_of(self.name)

    @property
    def effect_params(self):
        """The effects' parameters, their ranges set for the structure when `scales` are given
        (`jointcal.effects.Effect.rescale`; the library's ranges are the Ministack's)."""
        return tuple(p for e in self.effects for p in EFFECTS[e].params_for(dict(self.scales or ())))

    @property
    def sequence_dependent(self) -> bool:
        """Whether the model changes with the run's place in the test sequence."""
        return any(EFFECTS[e].sequence_dependent for e in self.effects)

    @cached_property
    def grown(self) -> ParamSpace:
        """The calibration's space with the effect's parameters appended (`ParamSpace.grow`)."""
        return self.space.grow_by(self.effect_params)

    @property
    def names(self) -> tuple[str, ...]:
        return self.grown.names

    def to_physical(self, u: NDArray) -> NDArray:
        """Unit cube (..., n) -> physical values (..., n)."""
        return self.grown.to_physical(u)

    def to_unit(self, theta: NDArray) -> NDArray:
        """Physical values (..., n) -> unit cube (..., n)."""
        return self.grown.to_unit(theta)


def candidate(name: str, space: ParamSpace, m: float, scales: Mapping[str, float] | None = None) -> Candidate:
    """The candidate of a model name ('baseline', an effect, or effects joined by '+'); `scales`
    (`structure_scales`) set its effects' ranges for a structure other than the Ministack."""
    effects_of(name)  # one sentence for an unknown name
    return Candidate(name, space, m, None if scales is None else tuple(sorted(scales.items())))


def structure_scales(best: Mapping, modal: pd.DataFrame) -> dict[str, float]:
    """The structure's scales the effects' ranges follow: its stuck stiffness K0 = k + KT (lbf/in), stuck
    frequency f0 (Hz) and largest amplitude measured q (in), from the calibration and the read-outs."""
    K0 = float(best["k"]) + float(best["KT"])
    return {"K0": K0, "f0": float(np.sqrt(K0 / float(best["m"])) / (2 * np.pi)),
            "q": float(pd.to_numeric(modal["q_in"], errors="coerce").max())}


def model_at(c: Candidate, theta: NDArray, row: Mapping) -> MinistackModel:
    """The model of parameter sets theta (n,) or (P, n) for the run of `row` (batched fields (P, 1))."""
    th = np.asarray(theta, dtype=float)
    values = c.grown.named(th, c.grown.extra, keepdims=th.ndim == 2)
    return apply_effect(c.grown.model(th, c.m), c.name, values, row)


def _drive(run: RunEnvelope) -> tuple:
    """The run's frames as `quasi_steady_runs` takes them: f, base, rate, dlog A/dt, direction."""
    rate, dlog = (run.rate, 0.0) if run.drive_rates is None else run.drive_rates
    return run.f_hz, run.base_g, rate, dlog, "up" if run.rate >= 0 else "down"


def _first_order_runs(c: Candidate, theta: NDArray, runs: Sequence[RunEnvelope],
                      model: MinistackModel | None = None) -> list[NDArray[np.complex128]]:
    """The first-order quasi-steady envelope at each run's frames, (P, n) or (n,) per run: one model for
    all runs, unless the candidate changes with the run's place in the sequence. model: the model of the
    first run (`model_at(c, theta, runs[0].row)`) when the caller has built it."""
    first = model_at(c, theta, runs[0].row) if model is None else model
    if c.sequence_dependent:
        return [quasi_steady_runs(first if i == 0 else model_at(c, theta, run.row), [_drive(run)])[0]
                for i, run in enumerate(runs)]
    return quasi_steady_runs(first, [_drive(run) for run in runs])


def observed(model: MinistackModel, T: NDArray, run: RunEnvelope) -> NDArray[np.complex128]:
    """What the run's response over reference reads of the model's base-rig envelope T, (P, n) or (n,).

    A base drive: T itself. A force or voltage: the model is driven by the equivalent base
    acceleration e R (e = -A(w) / G per frame, `RunEnvelope.equivalent_base`), and its response
    channel reads the mode's relative acceleration through the sensor s (gain and delay): e (T - s).
    """
    if run.equivalent_base is None:
        return T
    gain = np.asarray(model.sensor_gain, dtype=float)
    tau = np.asarray(model.sensor_delay_s, dtype=float)
    turn = np.exp(1j * delay_reference(run.row) * tau) if np.any(tau) else 1.0  # a voltage's A_c holds it at w_c
    return run.equivalent_base * turn * (T - gain * np.exp(-2j * np.pi * run.f_hz * tau))


def transient_factor(c: Candidate, theta: NDArray, run: RunEnvelope) -> NDArray[np.complex128] | None:
    """The run's sweep-transient factor at parameters theta (n,): the integrated swept envelope
    (`swept_transmissibility`) over the first-order one at each frame (None where nothing is integrated:
    a run without its drive)."""
    if run.drive is None or run.t_s is None:
        return None
    model = model_at(c, theta, run.row)
    swept = swept_transmissibility(model, run.drive, run.t_s, f_res_hz=float(run.row["f_res_hz"]), zeta=run_zeta(run.row))
    with np.errstate(all="ignore"):
        factor = swept / _first_order_runs(c, theta, [run], model)[0]
    return np.where(np.isfinite(factor), factor, 1.0)


def _run_residual(model: MinistackModel, T: NDArray, run: RunEnvelope, n_runs: int) -> NDArray:
    """Weighted magnitude (dB) and phase (deg) errors of the envelope T (transient included) at the run's frames."""
    d = observed(model, T, run) / run.T
    w = 1.0 / np.sqrt(2.0 * run.f_hz.size * n_runs)
    dm = 20 * np.log10(np.abs(d)) / run.sigma_db
    dp = np.degrees(np.angle(d)) / run.sigma_deg
    return np.concatenate([dm, dp], axis=-1) * w


@dataclass(frozen=True)
class Fit:
    """A fitted candidate: physical parameters, E over the fitted runs, and an approximate covariance."""

    name: str
    theta: NDArray[np.float64]
    E: float
    cov_unit: NDArray[np.float64]
    n_eval: int


@dataclass(frozen=True)
class Objective:
    """A candidate on one assembly's runs, linearised at theta_ref: E, its residuals, the prediction, the fit.

    The model's envelope is the first-order quasi-steady one at each frame (cheap, batched over
    parameter sets) times each run's sweep-transient factor taken at theta_ref (`transient_factor`:
    the slow flow integrated through the resonance over the first-order envelope). The runs hold
    measurements only; the factor is the objective's, refreshed in one place (`at`).

    Attributes
    ----------
    candidate : Candidate
    runs : tuple of RunEnvelope
    transient : tuple of (ndarray or None)
        Each run's factor at theta_ref (None: 1, the first-order envelope alone).
    theta_ref : ndarray or None
        Where the factors were taken (None: nowhere, every factor 1).
    """

    candidate: Candidate
    runs: tuple[RunEnvelope, ...]
    transient: tuple[NDArray[np.complex128] | None, ...] = ()
    theta_ref: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "runs", tuple(self.runs))
        if not self.transient:
            object.__setattr__(self, "transient", (None,) * len(self.runs))

    def at(self, theta: NDArray) -> Objective:
        """The same candidate and runs linearised at theta (n,): every run's transient factor taken there."""
        th = np.asarray(theta, dtype=float)
        return Objective(self.candidate, self.runs, tuple(transient_factor(self.candidate, th, r) for r in self.runs),
                         th)

    def subset(self, idx: Sequence[int]) -> Objective:
        """The objective on the runs `idx` (their factors kept)."""
        return Objective(self.candidate, tuple(self.runs[i] for i in idx), tuple(self.transient[i] for i in idx),
                         self.theta_ref)

    def predict(self, theta: NDArray, i: int) -> NDArray[np.complex128]:
        """Run i's measured quantity as the model gives it at its frames as the sweep shows it, (P, n) or (n,):
        the first-order envelope times the run's transient factor, `observed`."""
        c, run, k = self.candidate, self.runs[i], self.transient[i]
        model = model_at(c, theta, run.row)
        T = _first_order_runs(c, theta, [run], model)[0]
        return observed(model, T if k is None else T * k, run)

    def residuals(self, theta: NDArray) -> NDArray:
        """Residual vector whose sum of squares is E^2 (theta (n,) -> (m,), (P, n) -> (P, m))."""
        c, runs = self.candidate, self.runs
        with np.errstate(all="ignore"):
            model = model_at(c, theta, runs[0].row)  # its sensor (no effect changes it along the sequence)
            T = _first_order_runs(c, theta, runs, model)
            r = np.concatenate([_run_residual(model, t if k is None else t * k, run, len(runs))
                                for t, k, run in zip(T, self.transient, runs)], axis=-1)
        return np.where(np.isfinite(r), r, 1e3)

    def E(self, theta: NDArray) -> float:
        """E of the fast model at theta over the runs (the validation's definition)."""
        return float(np.sqrt(np.sum(self.residuals(theta) ** 2)))

    def fit(self, theta0: NDArray, *, starts: int = 3, max_nfev: int = 60, free_joint: bool = True,
            refresh: int = 0) -> Fit:
        """Bounded least squares of E^2 over the candidate's unit cube, from theta0 and effect start values.

        theta0 : (6,) or (n,) physical start, in the candidate's column order (the joint's parameters
        alone, or with effect values; the effect values it does not give default to their `start`).
        starts : effect starts tried (the `start` value and evenly spread points of the unit interval,
        for the effect parameters theta0 does not give). free_joint : False holds the joint parameters.
        refresh : times the transient factor is retaken (at theta0 first, then at each optimum,
        refitting from it); 0 keeps this objective's factors.
        """
        return refreshed_fit(self, theta0, starts, max_nfev, free_joint, refresh)


def refreshed_fit(obj, theta0: NDArray, starts: int, max_nfev: int, free_joint: bool, refresh: int) -> Fit:
    """An objective's fit (`Objective.fit`, `decays.DecayObjective.fit`): theta0 completed with the effects' start
    values, then `least_squares_fit` at the objective's factors, or, with refresh, at the factors retaken at the
    start (``obj.at``) and again at each optimum, refitting from it (from the optimum alone).

    The first fit is told which effect values theta0 gave: the others are also started from spread points
    and their grids (`least_squares_fit`), with refresh as without."""
    space = obj.candidate.grown
    given = dict(zip(space.names, map(float, theta0)))  # the space's leading columns
    th0 = space.vector(given, default={p.name: p.start for p in obj.candidate.effect_params})
    if refresh:  # the first fit knows which effect values theta0 left out: their starts (spread, grid) are tried
        fit = least_squares_fit(obj.at(th0), th0, given, starts, max_nfev, free_joint)
        for _ in range(refresh):
            again = obj.at(fit.theta).fit(fit.theta, starts=1, max_nfev=max_nfev, free_joint=free_joint)
            fit = replace(again, n_eval=again.n_eval + fit.n_eval)
        return fit
    return least_squares_fit(obj, th0, given, starts, max_nfev, free_joint)


def _grid_start(obj, u0: NDArray, grids: Mapping[str, int]) -> NDArray | None:
    """The best point of the even grid over the unit-cube ranges of the parameters `grids` names (points each),
    the others at u0: one batched evaluation of the objective (None without a grid)."""
    if not grids:
        return None
    c = obj.candidate
    axes = [np.linspace(1e-6, 1 - 1e-6, grids[n]) if n in grids else np.array([u0[i]])
            for i, n in enumerate(c.grown.names)]
    U = np.stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")], axis=-1)
    with np.errstate(all="ignore"):
        cost = np.sum(obj.residuals(c.to_physical(U)) ** 2, axis=-1)
    return U[int(np.nanargmin(cost))].copy() if np.isfinite(cost).any() else None


def least_squares_fit(obj: Objective, th0: NDArray, given: Mapping[str, float], starts: int, max_nfev: int,
                   free_joint: bool) -> Fit:
    """`Objective.fit` at fixed transient factors: trust-region least squares from th0 and the effect starts,
    the Jacobian one batched call of the fast model over the perturbed parameter sets."""
    c, space = obj.candidate, obj.candidate.grown
    u0 = np.clip(c.to_unit(th0), 1e-6, 1 - 1e-6)
    # beta is barely identifiable from envelopes and sits on its floor in most joints: held
    free = space.free_mask(HELD if free_joint else (*PARAMS, *HELD))
    inits = [u0]
    spread = np.array([p not in given for p in space.names])  # effect parameters without a value in theta0
    if spread.any():
        for s in np.linspace(0.15, 0.85, max(0, starts - 1)):
            u = u0.copy()
            u[spread] = s
            inits.append(u)
        u = _grid_start(obj, u0, {p.name: p.grid for p in c.effect_params if p.grid and p.name not in given})
        if u is not None:
            inits.append(u)
    h = 1e-5
    count = [0]
    last = {}  # the latest evaluation: least squares asks the Jacobian where it has just evaluated

    def full(v):
        u = u0.copy()
        u[free] = v
        return u

    def fun(v):
        count[0] += 1
        last["v"], last["r"] = np.array(v, dtype=float), obj.residuals(c.to_physical(full(v)))
        return last["r"]

    def jac(v):
        u = full(v)
        idx = np.flatnonzero(free)
        U = np.repeat(u[None], idx.size, axis=0)
        step = np.where(u[idx] + h <= 1, h, -h)
        U[np.arange(idx.size), idx] += step
        count[0] += 1
        R = obj.residuals(c.to_physical(U))
        r0 = last["r"] if "v" in last and np.array_equal(last["v"], v) else fun(v)
        return ((R - r0) / step[:, None]).T

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
    cov = np.zeros((space.ndim, space.ndim))
    cov[np.ix_(free, free)] = cov_f
    u = full(best.x)
    return Fit(c.name, c.to_physical(u), float(np.sqrt(2 * best.cost)), cov, count[0])
