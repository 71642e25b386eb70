"""Log-posterior of the joint parameters and the two noise scales, vectorised over walkers.

The sampler moves in the coordinates y of `jointcal.posterior.coords` (log10 K0,
log10(KT/k), chi, log10 S_ref, log10 beta, log10 zeta_v) followed by log10 sigma_f and
log10 sigma_zeta, the relative noise scales of the measured frequency and damping
(`LogPosterior.names`); `LogPosterior.to_x` maps a chain to the GA's space x (log10 Fs,
log10 KT, chi, log10 beta, log10 k, log10 zeta_v, then the two noise coordinates).

Likelihood: independent Gaussians on the relative residuals,
r_f,i = (f_i - f~(q_i))/f_i ~ N(0, sigma_f^2) and r_z,i = (zeta_i - zeta~(q_i))/zeta_i
~ N(0, sigma_zeta^2), with the model and viscous convention of the GA. Unlike eq. 3.9
there is no weight eta: each residual counts by its noise.

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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..calibrate.data import ModalData
from ..calibrate.objective import Model, predict
from ..calibrate.space import ParamSpace
from .coords import Y_NAMES, log_det_dy_dx, x_to_y, y_to_x

__all__ = ["LogPosterior"]


@dataclass(frozen=True)
class LogPosterior:
    """Vectorised log-posterior (callable), for `emcee.EnsembleSampler(..., vectorize=True)`.

    Parameters
    ----------
    data : ModalData
        Measured q (in), f (Hz), zeta per usable run, and the noise floors.
    space : ParamSpace
        Bounds of the six joint parameters.
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
            raise ValueError(f"noise floors {10.0**lo} must be finite and below noise_max {self.noise_max}")

    @property
    def q_ref(self) -> float:
        """Reference amplitude of the S_ref coordinate: geometric mean of the measured q, in."""
        return float(np.exp(np.mean(np.log(self.data.q))))

    @property
    def names(self) -> tuple[str, ...]:
        """Sampler coordinate names (y, then log10_sigma_f, log10_sigma_zeta)."""
        return (*Y_NAMES, "log10_sigma_f", "log10_sigma_zeta")

    @property
    def x_names(self) -> tuple[str, ...]:
        """Names of the `to_x` columns (GA space, then the noise coordinates)."""
        return (*self.space.x_names, "log10_sigma_f", "log10_sigma_zeta")

    @property
    def ndim(self) -> int:
        """Number of sampled coordinates (8)."""
        return self.space.ndim + 2

    @property
    def noise_lo(self) -> NDArray[np.float64]:
        """log10 of the noise floors, shape (2,)."""
        return np.log10(np.asarray(self.data.rel_noise, dtype=float))

    @property
    def lower(self) -> NDArray[np.float64]:
        """Prior lower bounds in x (GA space + noise), shape (ndim,)."""
        return np.r_[self.space.x_lo, self.noise_lo]

    @property
    def upper(self) -> NDArray[np.float64]:
        """Prior upper bounds in x (GA space + noise), shape (ndim,)."""
        return np.r_[self.space.x_hi, np.log10(self.noise_max)]

    def to_x(self, y: ArrayLike) -> NDArray[np.float64]:
        """Sampler points (..., ndim) to GA-space + noise coordinates (..., ndim)."""
        y = np.asarray(y, dtype=float)
        return np.concatenate([y_to_x(y[..., :6], self.q_ref), y[..., 6:]], axis=-1)

    def to_y(self, x: ArrayLike) -> NDArray[np.float64]:
        """Inverse of `to_x`."""
        x = np.asarray(x, dtype=float)
        return np.concatenate([x_to_y(x[..., :6], self.q_ref), x[..., 6:]], axis=-1)

    def physical(self, x: ArrayLike) -> NDArray[np.float64]:
        """GA-space + noise coordinates (..., ndim) to (Fs, KT, chi, beta, k, zeta_v, sigma_f, sigma_zeta)."""
        x = np.asarray(x, dtype=float)
        log = np.r_[self.space.is_log, True, True]
        return np.where(log, 10.0**x, x)

    def residuals(self, x: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Relative residuals of f and zeta, each (W, N), at GA-space points x (W, 6 or ndim)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        theta = self.physical(np.concatenate([x[:, :6], np.zeros((len(x), 2))], axis=1))[:, :6]
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
        r_f, r_z = self.residuals(x[ok])
        s_f, s_z = 10.0 ** x[ok, -2], 10.0 ** x[ok, -1]
        n = self.data.q.size
        with np.errstate(all="ignore"):
            lp = (-0.5 * np.sum(r_f**2, axis=1) / s_f**2 - n * np.log(s_f)
                  - 0.5 * np.sum(r_z**2, axis=1) / s_z**2 - n * np.log(s_z)
                  - log_det_dy_dx(y[ok]))  # prior uniform in x -> density 1/(chi+1) in y
        out[ok] = np.where(np.isfinite(lp), lp, -np.inf)
        return out
