"""Segalman's four-parameter Iwan joint: parameters, closed forms, exact hysteresis.

References are to the paper's equations (Kuether & Najera, ch. 3): the power-law
density (3.3), the force (3.4) and the parameter map (3.5)-(3.7).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _masing

__all__ = [
    "IwanParams",
    "derived",
    "backbone",
    "backbone_stiffness",
    "dissipation",
    "force_history",
]


@dataclass(frozen=True)
class IwanParams:
    """Four-parameter Iwan joint.

    Parameters
    ----------
    Fs : float
        Slip (macroslip) force, lbf.
    KT : float
        Joint stiffness with no slip, lbf/in.
    chi : float
        Power-law exponent of the slider density, -1 < chi <= 0; the dissipation
        per cycle grows as amplitude**(chi + 3) in microslip.
    beta : float
        Ratio of the macroslip delta to the power-law part, >= 0.
    """

    Fs: float
    KT: float
    chi: float
    beta: float

    def __post_init__(self) -> None:
        Fs, KT, chi, beta = (np.asarray(v) for v in (self.Fs, self.KT, self.chi, self.beta))  # arrays: a batch
        if not np.all((Fs > 0) & np.isfinite(Fs)):
            raise ValueError(f"Iwan Fs must be a positive force in lbf, got {self.Fs!r}.")
        if not np.all((KT > 0) & np.isfinite(KT)):
            raise ValueError(f"Iwan KT must be a positive stiffness in lbf/in, got {self.KT!r}.")
        if not np.all((-1.0 < chi) & (chi <= 0.0)):
            raise ValueError(f"Iwan chi must lie in (-1, 0], got {self.chi!r}.")
        if not np.all((beta >= 0) & np.isfinite(beta)):
            raise ValueError(f"Iwan beta must be >= 0, got {self.beta!r}.")


def derived(Fs: ArrayLike, KT: ArrayLike, chi: ArrayLike, beta: ArrayLike):
    """Density parameters of the four-parameter Iwan element.

    Parameters
    ----------
    Fs, KT, chi, beta : array_like
        Iwan parameters (lbf, lbf/in, -, -); broadcast together.

    Returns
    -------
    phi_max : ndarray
        Largest slider slip displacement, in (eq. 3.7).
    R : ndarray
        Power-law density coefficient, lbf / in**(chi + 2) (eq. 3.5).
    S : ndarray
        Strength of the delta at phi_max, lbf/in (eq. 3.6).
    """
    Fs, KT, chi, beta = (np.asarray(a, dtype=float) for a in (Fs, KT, chi, beta))
    c = beta + (chi + 1.0) / (chi + 2.0)
    phi_max = Fs * (1.0 + beta) / (KT * c)  # eq. 3.7
    R = Fs * (chi + 1.0) / (phi_max ** (chi + 2.0) * c)  # eq. 3.5
    S = (Fs / phi_max) * beta / c  # eq. 3.6
    return phi_max, R, S


def backbone(u: ArrayLike, p: IwanParams) -> NDArray[np.float64]:
    """Virgin (monotonic loading) force F_b(u), lbf, odd in u (in).

    F_b = KT u - R u**(chi+2) / ((chi+1)(chi+2)) for |u| < phi_max, Fs beyond.
    """
    u = np.asarray(u, dtype=float)
    phi_max, R, _ = derived(p.Fs, p.KT, p.chi, p.beta)
    a = np.minimum(np.abs(u), phi_max)
    F = p.KT * a - R * a ** (p.chi + 2.0) / ((p.chi + 1.0) * (p.chi + 2.0))
    return np.sign(u) * np.where(np.abs(u) >= phi_max, p.Fs, F)


def backbone_stiffness(u: ArrayLike, p: IwanParams) -> NDArray[np.float64]:
    """Tangent dF_b/du of the virgin backbone, lbf/in (0 past macroslip)."""
    u = np.abs(np.asarray(u, dtype=float))
    phi_max, R, _ = derived(p.Fs, p.KT, p.chi, p.beta)
    a = np.minimum(u, phi_max)
    return np.where(u >= phi_max, 0.0, p.KT - R * a ** (p.chi + 1.0) / (p.chi + 1.0))


def dissipation(q: ArrayLike, Fs, KT, chi, beta) -> NDArray[np.float64]:
    """Energy dissipated per symmetric cycle of displacement amplitude q, lbf*in.

    D = 4 R q**(chi+3) / ((chi+2)(chi+3)) for q <= phi_max; beyond, the power-law
    sliders dissipate 4R(q u**(chi+2)/(chi+2) - u**(chi+3)/(chi+3)) with u = phi_max
    and the delta adds 4 S phi_max (q - phi_max). Broadcasts over q and parameters.
    """
    q = np.asarray(q, dtype=float)
    chi = np.asarray(chi, dtype=float)
    phi_max, R, S = derived(Fs, KT, chi, beta)
    u = np.minimum(q, phi_max)
    D = 4.0 * R * (q * u ** (chi + 2.0) / (chi + 2.0) - u ** (chi + 3.0) / (chi + 3.0))
    return D + 4.0 * S * phi_max * np.maximum(q - phi_max, 0.0)


def force_history(u: ArrayLike, p: IwanParams) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Exact Iwan force along any displacement history (Masing/Madelung rules).

    Parameters
    ----------
    u : array_like, shape (N,)
        Joint displacement history, in, starting from the virgin state at u = 0.
        Reversals are taken at the samples where the motion changes direction.
    p : IwanParams

    Returns
    -------
    F : ndarray, shape (N,)
        Joint force, lbf.
    K : ndarray, shape (N,)
        Tangent stiffness on the current branch, lbf/in.
    """
    u = np.ascontiguousarray(u, dtype=float)
    if not np.all(np.isfinite(u)):
        raise ValueError("force_history: the displacement history holds NaN or inf.")
    phi_max, R, _ = derived(p.Fs, p.KT, p.chi, p.beta)
    R1, e = _masing.kernel_constants(R, p.chi)  # floats throughout: one compiled signature
    return _masing.force_history(u, float(p.KT), float(R1), float(e), float(phi_max), float(p.Fs))
