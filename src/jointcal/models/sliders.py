"""Discretised parallel-series Iwan (Jenkins sliders): a test reference only.

The power-law density (eq. 3.3) is split into bins of equal stiffness; each bin is one
Jenkins element whose slip displacement is the bin's force-weighted mean, so that a
fully slipped bin carries exactly the density's force. The delta at phi_max is one
more slider of stiffness S. This is what slider codes (e.g. tmdsimpy) do, and it is
only as accurate as the number of sliders allows; `jointcal.models.iwan` is exact.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .iwan import IwanParams, derived

__all__ = ["slider_set", "slider_force_history"]


def slider_set(p: IwanParams, n: int, *, scheme: str = "equal_stiffness"):
    """Slider stiffnesses (lbf/in) and slip displacements (in), shape (n + 1,).

    ``scheme="equal_stiffness"`` bins in t = phi**(chi+1) (each bin the same stiffness,
    resolving the singular density at small phi); ``scheme="uniform"`` bins phi
    uniformly with midpoint sliders (tmdsimpy's scheme). The last slider is the delta.
    """
    phi_max, R, S = (float(a) for a in derived(p.Fs, p.KT, p.chi, p.beta))
    a = p.chi + 1.0
    if scheme == "equal_stiffness":
        edges = (np.linspace(0.0, 1.0, n + 1) * phi_max**a) ** (1.0 / a)
    elif scheme == "uniform":
        edges = np.linspace(0.0, phi_max, n + 1)
    else:
        raise ValueError(f"slider_set: unknown scheme {scheme!r}; use 'equal_stiffness' or 'uniform'.")
    if scheme == "uniform":
        phi = 0.5 * (edges[1:] + edges[:-1])
        k = R * phi**p.chi * np.diff(edges)
    else:  # exact bin stiffness at the bin's force-weighted mean slip displacement
        k = R * (edges[1:] ** a - edges[:-1] ** a) / a
        phi = R * (edges[1:] ** (a + 1) - edges[:-1] ** (a + 1)) / (a + 1) / k
    return np.append(k, S), np.append(phi, phi_max)


def slider_force_history(u: ArrayLike, k: NDArray, phi: NDArray) -> NDArray[np.float64]:
    """Force (lbf) of Jenkins sliders (stiffness k, slip phi) along history u (in).

    Each slider's anchor x follows the stick/slip law (eq. 3.2):
    |u - x| <= phi, x moves only when the spring is at its slip displacement.
    """
    u = np.asarray(u, dtype=float)
    x = np.zeros_like(k)
    F = np.empty(u.shape)
    for i, ui in enumerate(u):
        x = np.clip(x, ui - phi, ui + phi)
        F[i] = np.dot(k, ui - x)
    return F
