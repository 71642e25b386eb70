"""Sampler coordinates aligned with what amplitude-dependent f and zeta can identify.

Below macroslip (q < phi_max, which holds for the paper's data: q <= 0.25 phi_max) the
harmonic-balance and QSMA frequency and damping depend on the joint only through four
combinations: the stuck stiffness K0 = k + KT, the softening R q^(chi+1) (eq. 3.5's R,
with chi), chi and zeta_v. Fs, KT, beta and k one by one are identified only through the
onset of macroslip and the bounds. In the GA's space (log10 Fs, log10 KT, chi, log10
beta, log10 k, log10 zeta_v) that leaves a curved two-dimensional ridge, along which
emcee's stretch move crawls (tau grew with the chain: never 50 tau). The sampler
therefore moves in

    y = (log10 K0, log10(KT/k), chi, log10 S_ref, log10 beta, log10 zeta_v),
    S_ref = R q_ref^(chi+1)  (lbf/in: the joint's stiffness loss scale at q_ref),

q_ref the geometric mean of the measured amplitudes, where the identified directions
are axis-like and the unidentified ones (log10(KT/k), log10 beta) are nearly flat.
The map is one-to-one with |det dy/dx| = chi + 1, so the GA-space prior (uniform in x
within the bounds) is, in y, proportional to 1/(chi + 1) on the image of the bounds.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Y_NAMES", "x_to_y", "y_to_x", "log_det_dy_dx"]

Y_NAMES = ("log10_K0", "log10_KT_over_k", "chi", "log10_S_ref", "log10_beta", "log10_zeta_v")


def _log10_R_rest(lKT, chi, lbeta):
    """log10 R + (chi+1) log10 Fs, from eqs. 3.5 and 3.7."""
    beta = 10.0**lbeta
    c = beta + (chi + 1.0) / (chi + 2.0)
    return np.log10(chi + 1.0) + (chi + 2.0) * lKT + (chi + 1.0) * np.log10(c) - (chi + 2.0) * np.log10(1.0 + beta)


def x_to_y(x: ArrayLike, q_ref: float) -> NDArray[np.float64]:
    """GA-space coordinates (..., 6) to sampler coordinates (..., 6).

    Parameters
    ----------
    x : array_like, shape (..., 6)
        log10 Fs (lbf), log10 KT (lbf/in), chi, log10 beta, log10 k (lbf/in), log10 zeta_v.
    q_ref : float
        Reference amplitude, in.
    """
    x = np.asarray(x, dtype=float)
    lFs, lKT, chi, lb, lk, lzv = np.moveaxis(x, -1, 0)
    lK0 = np.logaddexp(lKT * np.log(10.0), lk * np.log(10.0)) / np.log(10.0)
    lR = _log10_R_rest(lKT, chi, lb) - (chi + 1.0) * lFs  # eq. 3.5
    return np.stack([lK0, lKT - lk, chi, lR + (chi + 1.0) * np.log10(q_ref), lb, lzv], axis=-1)


def y_to_x(y: ArrayLike, q_ref: float) -> NDArray[np.float64]:
    """Inverse of `x_to_y` (NaN where chi <= -1)."""
    y = np.asarray(y, dtype=float)
    lK0, a, chi, lS, lb, lzv = np.moveaxis(y, -1, 0)
    split = np.logaddexp(0.0, a * np.log(10.0)) / np.log(10.0)  # log10(1 + KT/k)
    lKT, lk = lK0 + a - split, lK0 - split
    with np.errstate(invalid="ignore", divide="ignore"):
        lR = lS - (chi + 1.0) * np.log10(q_ref)
        lFs = (_log10_R_rest(lKT, chi, lb) - lR) / (chi + 1.0)  # eq. 3.5 solved for Fs
    return np.stack([lFs, lKT, chi, lb, lk, lzv], axis=-1)


def log_det_dy_dx(y: ArrayLike) -> NDArray[np.float64]:
    """ln |det dy/dx| = ln(chi + 1) for sampler points y (..., 6) in `Y_NAMES` order."""
    chi = np.asarray(y, dtype=float)[..., Y_NAMES.index("chi")]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.log(chi + 1.0)
