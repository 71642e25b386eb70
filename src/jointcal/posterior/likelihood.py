"""Log-posterior of the joint parameters and the two noise scales, vectorised over walkers.

The sampler moves in the coordinates y of `jointcal.posterior.coords` (log10 K0,
log10(KT/k), chi, log10 S_ref, log10 beta, log10 zeta_v) followed by log10 sigma_f and
log10 sigma_zeta, the relative noise scales of the measured frequency and damping
(`LogPosterior.names`); `LogPosterior.to_x` maps a chain to the GA's space x (log10 Fs,
log10 KT, chi, log10 beta, log10 k, log10 zeta_v, then the two noise coordinates). The
space may be grown (`ParamSpace.grow`): the joint's columns are found by name and mapped
to y, any other column is sampled in x as it is (uniform prior within its bounds); the
modal read-outs see the joint only, so a grown column is left to its prior here.

Likelihood: independent Gaussians on the relative residuals,
r_f,i = (f_i - f~(q_i))/f_i ~ N(0, sigma_f^2) and r_z,i = (zeta_i - zeta~(q_i))/zeta_i
~ N(0, sigma_zeta^2), with the model and viscous convention of the GA. Unlike eq. 3.9
there is no weight eta: each residual counts by its noise. A point of weight w_i (a ring-down's
k windows, 1/k each: `jointcal.calibrate._readouts`) enters with its Gaussian raised to w_i, so
that a ring-down counts as one read-out, as in the GA; with one point per run every w_i is 1.

The noise scales are sampled, not fixed. Their priors are log-uniform from the pooled
repeat scatter of the modal stage (floored, `ModalData.rel_noise`) up to ``noise_max``:
the data cannot be less noisy than their repeats show, but model error (a non-Iwan
effect, sweep-rate bias, drift between assemblies) can make them look noisier, and a
noise scale fixed at the repeat scatter would then give falsely narrow intervals.
Priors on the joint parameters: uniform in x within the GA's bounds, i.e. log-uniform
for Fs, KT, beta, k, zeta_v and uniform for chi; in y that density carries the Jacobian
1/(chi + 1).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..calibrate.data import ModalData
from ..calibrate.objective import Model, predict
from ..calibrate.space import PARAMS, ParamSpace
from .coords import Y_NAMES, log_det_dy_dx, x_to_y, y_to_x

__all__ = ["NOISE", "LogPosterior", "ResidualPosterior"]

NOISE = ("sigma_f", "sigma_zeta")  # the relative noise scales sampled after the space's parameters


@dataclass(frozen=True)
class LogPosterior:
    """Vectorised log-posterior (callable), for `emcee.EnsembleSampler(..., vectorize=True)`.

    Parameters
    ----------
    data : ModalData
        Measured q (in), f (Hz), zeta per usable run, and the noise floors.
    space : ParamSpace
        Bounds of the six joint parameters, and of any grown onto them.
    m : float
        Slug mass, lbf s^2/in.
    model, viscous : str
        As the GA (`jointcal.calibrate.objective.predict`).
    noise_max : (float, float)
        Upper bounds of sigma_f and sigma_zeta (relative).
    """

    data: ModalData
    space: ParamSpace
    m: float
    model: Model = "harmonic_balance"
    viscous: str = "dashpot"
    noise_max: tuple[float, float] = (0.05, 0.5)

    def __post_init__(self) -> None:
        lo = self.noise_lo
        if not (np.all(np.isfinite(lo)) and np.all(10.0**lo < np.asarray(self.noise_max))):
            raise ValueError(f"noise floors {10.0**lo} must be finite and below noise_max {self.noise_max}; raise "
                             "posterior.noise_max, or find the runs that scatter (jointcal.posterior.noise.data_problem)")

    @cached_property  # read at every evaluation: computed once
    def q_ref(self) -> float:
        """Reference amplitude of the S_ref coordinate: geometric mean of the measured q, in."""
        return float(np.exp(np.mean(np.log(self.data.q))))

    @cached_property  # read at every evaluation: computed once
    def joint(self) -> list[int]:
        """Columns of the joint's parameters (`PARAMS` order) in x and of their y coordinates."""
        return [self.space.index(p) for p in PARAMS]

    @property
    def names(self) -> tuple[str, ...]:
        """Sampler coordinate names (y in the joint's columns, x in any other, then log10_sigma_f,
        log10_sigma_zeta)."""
        names = list(self.space.x_names)
        for i, y in zip(self.joint, Y_NAMES):
            names[i] = y
        return (*names, "log10_sigma_f", "log10_sigma_zeta")

    @property
    def x_names(self) -> tuple[str, ...]:
        """Names of the `to_x` columns (GA space, then the noise coordinates)."""
        return (*self.space.x_names, "log10_sigma_f", "log10_sigma_zeta")

    @property
    def sample_names(self) -> tuple[str, ...]:
        """Names of the `physical` columns: the space's parameters, then sigma_f, sigma_zeta."""
        return (*self.space.names, *NOISE)

    @property
    def ndim(self) -> int:
        """Number of sampled coordinates (8 for the joint's space)."""
        return self.space.ndim + 2

    @cached_property  # read at every evaluation: computed once
    def noise_lo(self) -> NDArray[np.float64]:
        """log10 of the noise floors, shape (2,)."""
        return np.log10(np.asarray(self.data.rel_noise, dtype=float))

    @cached_property  # read at every evaluation: computed once
    def lower(self) -> NDArray[np.float64]:
        """Prior lower bounds in x (GA space + noise), shape (ndim,)."""
        return np.r_[self.space.x_lo, self.noise_lo]

    @cached_property  # read at every evaluation: computed once
    def upper(self) -> NDArray[np.float64]:
        """Prior upper bounds in x (GA space + noise), shape (ndim,)."""
        return np.r_[self.space.x_hi, np.log10(self.noise_max)]

    def to_x(self, y: ArrayLike) -> NDArray[np.float64]:
        """Sampler points (..., ndim) to GA-space + noise coordinates (..., ndim)."""
        y = np.asarray(y, dtype=float)
        x = y.copy()
        x[..., self.joint] = y_to_x(y[..., self.joint], self.q_ref)
        return x

    def to_y(self, x: ArrayLike) -> NDArray[np.float64]:
        """Inverse of `to_x`."""
        x = np.asarray(x, dtype=float)
        y = x.copy()
        y[..., self.joint] = x_to_y(x[..., self.joint], self.q_ref)
        return y

    def physical(self, x: ArrayLike) -> NDArray[np.float64]:
        """GA-space + noise coordinates (..., ndim) to physical values (the space's names, sigma_f, sigma_zeta)."""
        x = np.asarray(x, dtype=float)
        log = np.r_[self.space.is_log, True, True]
        return np.where(log, 10.0**x, x)

    @cached_property  # read at every evaluation: computed once
    def _is_log(self) -> NDArray[np.bool_]:
        """`space.is_log`, shape (space.ndim,)."""
        return self.space.is_log

    @cached_property  # read at every evaluation: computed once
    def _root_w(self) -> NDArray[np.float64] | None:
        """sqrt of the points' weights, shape (N,), or None when every point weighs 1."""
        return None if self.data.weight is None else np.sqrt(self.data.w)

    def residuals(self, x: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Relative residuals of f and zeta, each (W, N), at GA-space points x (W, space.ndim or ndim)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        xs = x[:, :self.space.ndim]
        theta = np.where(self._is_log, 10.0 ** xs, xs)[:, self.joint]  # the joint's columns (`ParamSpace.joint`)
        with np.errstate(all="ignore"):
            f_m, z_m = predict(theta, self.data.q, m=self.m, model=self.model,
                               viscous=self.viscous)  # type: ignore[arg-type]
        return (self.data.f - f_m) / self.data.f, (self.data.zeta - z_m) / self.data.zeta

    def __call__(self, y: ArrayLike) -> NDArray[np.float64]:
        """log p(y | data) up to a constant, shape (W,), for sampler points y (W, ndim); -inf outside the prior."""
        y = np.atleast_2d(np.asarray(y, dtype=float))
        x = self.to_x(y)
        out = np.full(y.shape[0], -np.inf)
        ok = np.all(np.isfinite(x) & (x >= self.lower) & (x <= self.upper), axis=1)
        if not ok.any():
            return out
        x_ok = x if ok.all() else x[ok]
        r_f, r_z = self.residuals(x_ok)
        s_f, s_z = 10.0 ** x_ok[:, -2], 10.0 ** x_ok[:, -1]
        n = self.data.q.size
        if self._root_w is not None:  # each point's Gaussian to the power of its weight
            n = self.data.n_readouts
            r_f, r_z = r_f * self._root_w, r_z * self._root_w
        with np.errstate(all="ignore"):
            lp = (-0.5 * np.sum(r_f**2, axis=1) / s_f**2 - n * np.log(s_f)
                  - 0.5 * np.sum(r_z**2, axis=1) / s_z**2 - n * np.log(s_z)
                  - log_det_dy_dx((y if ok.all() else y[ok])[:, self.joint]))  # prior uniform in x -> 1/(chi+1) in y
        out[ok] = np.where(np.isfinite(lp), lp, -np.inf)
        return out


@dataclass(frozen=True)
class ResidualPosterior:
    """Vectorised log-posterior of any space from residuals already divided by their scatter.

    Prior: uniform on the unit cube of `space` (its bounds and scaling) in the `free`
    columns; the others are held at the unit point `at`. Likelihood: the residual vector r
    (m,) of a parameter set has sum(r^2) = E^2 (each of the n_res entries a measured
    quantity over its repeat scatter, divided by sqrt(n_res)), and

        log L = -n_res E^2 / (2 T),  T = max(E_opt^2, 1),

    the Gauss-Newton convention: a model that misses by more than the scatter gets
    intervals as wide as its misfit (T is its squared misfit at the optimum).

    Parameters
    ----------
    space : ParamSpace
        The parameters sampled (e.g. the joint's grown by an effect's).
    residuals : callable
        Physical parameter sets (P, n) -> residual vectors (P, m).
    n_res : int
        Number of residuals m.
    temperature : float
        T above (>= 1).
    at : ndarray, shape (n,)
        Unit-cube values of the held columns.
    free : ndarray of bool, shape (n,)
        Columns sampled.
    """

    space: ParamSpace
    residuals: object
    n_res: int
    temperature: float
    at: NDArray[np.float64]
    free: NDArray[np.bool_]

    @property
    def ndim(self) -> int:
        """Number of sampled coordinates (the free columns)."""
        return int(np.sum(self.free))

    def unit(self, v: ArrayLike) -> NDArray[np.float64]:
        """Sampler points (P, ndim) to unit-cube points of the whole space (P, n)."""
        return self.space.embed(v, self.at, self.free)

    def physical(self, v: ArrayLike) -> NDArray[np.float64]:
        """Sampler points (P, ndim) to physical parameter sets (P, n) in `space.names` order."""
        return self.space.to_physical(self.unit(v))

    def misfit_unit(self, u: ArrayLike) -> NDArray[np.float64]:
        """E^2 of unit-cube points of the whole space u (P, n), shape (P,) (a GA objective)."""
        return np.sum(self.residuals(self.space.to_physical(u)) ** 2, axis=-1)  # type: ignore[operator]

    def misfit(self, v: ArrayLike) -> NDArray[np.float64]:
        """E^2 of sampler points v (P, ndim), shape (P,)."""
        return self.misfit_unit(self.unit(v))

    def __call__(self, v: ArrayLike) -> NDArray[np.float64]:
        """log p(v | data) up to a constant, shape (P,); -inf outside the unit cube."""
        v = np.atleast_2d(np.asarray(v, dtype=float))
        inside = np.all((v >= 0.0) & (v <= 1.0), axis=1)
        out = np.full(v.shape[0], -np.inf)
        if inside.any():
            out[inside] = -0.5 * self.n_res * self.misfit(v[inside]) / self.temperature
        return out
