"""Numba kernel of the amplitude curves (private; see `jointcal.models.amplitude`).

One loop over parameter sets and amplitudes evaluates what `amplitude.harmonic_balance` and
`amplitude.qsma` write as whole-array numpy expressions, with the same operations in the same
order, but for the powers: one per point, u^(chi+2) with u = min(q, phi_max), gives u^(chi+3)
and, below macroslip, q^(chi+1) by a product or a quotient. The values agree with the numpy
expressions to rounding (a few units in the last place; the quadrature's sum also runs in another
order: tests/models/test_amplitude_kernel.py).

The kernel runs over parameter sets (rows) and amplitudes (columns): the density parameters and
J(chi, 1), which below macroslip is all the quadrature gives, are computed once per row, so a
population at N amplitudes costs P evaluations of the quadrature, not P * N (as
`amplitude._J_broadcast`). Any other broadcast is one parameter set per point (N = 1).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ._envelope_kernel import _J, _jenkins

__all__: list[str] = []

PI = np.pi


@njit(cache=True, inline="always")
def _minimum(a, b):
    """np.minimum of two floats: NaN if either is NaN (Python's min keeps the first)."""
    if a != a or b != b:
        return a + b
    return a if a <= b else b


@njit(cache=True, inline="always")
def _maximum(a, b):
    """np.maximum of two floats: NaN if either is NaN."""
    if a != a or b != b:
        return a + b
    return a if a >= b else b


@njit(cache=True, error_model="numpy")
def curves(q, theta, harmonic, dashpot, nodes, weights, f, zeta):
    """Frequency (Hz) and damping ratio of parameter sets (rows) at amplitudes (columns).

    Parameters
    ----------
    q : ndarray, shape (P, N) or (1, N), float64, C-contiguous
        Modal amplitudes, in: row r holds those of parameter set r (one row: the same for all).
    theta : ndarray, shape (P, 7), float64, C-contiguous
        Fs (lbf), KT (lbf/in), chi, beta, k (lbf/in), zeta_v, m (lbf s^2/in) per parameter set.
    harmonic : bool
        True: first-harmonic balance (`harmonic_balance`); False: QSMA (`qsma`).
    dashpot : bool
        True: the dashpot convention zeta_v omega_0 / omega; False: zeta_v added as it is.
    nodes, weights : ndarray, shape (16,)
        Gauss-Legendre rule on [0, 1] (`amplitude._NODES`, `amplitude._WEIGHTS`).
    f, zeta : ndarray, shape (P, N)
        Outputs: frequency, Hz, and damping ratio.
    """
    one = q.shape[0] == 1
    for r in range(theta.shape[0]):
        Fs, KT, chi, beta, k, zeta_v, m = (theta[r, 0], theta[r, 1], theta[r, 2], theta[r, 3], theta[r, 4],
                                           theta[r, 5], theta[r, 6])
        c = beta + (chi + 1.0) / (chi + 2.0)  # eqs. 3.5-3.7, as `iwan.derived`
        phi_max = Fs * (1.0 + beta) / (KT * c)  # eq. 3.7
        R = Fs * (chi + 1.0) / (phi_max ** (chi + 2.0) * c)  # eq. 3.5
        S = (Fs / phi_max) * beta / c  # eq. 3.6
        J1 = _J(chi, 1.0, nodes, weights) if harmonic else np.nan  # J below macroslip: chi's alone
        omega0 = np.sqrt((k + KT) / m)
        for j in range(q.shape[1]):
            x = q[0 if one else r, j]
            u = _minimum(x, phi_max)
            pu = u ** (chi + 2.0)  # one power per point: u^(chi+3) = pu u, and q^(chi+1) = pu / q below macroslip
            if harmonic:  # k_df = k + KT - R q^(chi+1) J(min(1, phi_max/q)) - S (1 - g(phi_max/q))
                smax = _minimum(1.0, phi_max / x)
                J = J1 if smax >= 1.0 else _J(chi, smax, nodes, weights)
                k_eff = k + KT - R * (pu / x if x <= phi_max else x ** (chi + 1.0)) * J
                if x > phi_max:
                    k_eff = k_eff - S * (1.0 - _jenkins(phi_max / x))
            else:  # secant: k + F_b(q) / q
                Fb = Fs if x >= phi_max else KT * u - R * pu / ((chi + 1.0) * (chi + 2.0))
                k_eff = k + Fb / x
            omega = np.sqrt(k_eff / m)
            D = 4.0 * R * (x * pu / (chi + 2.0) - pu * u / (chi + 3.0))
            D = D + 4.0 * S * phi_max * _maximum(x - phi_max, 0.0)  # Masing dissipation (`iwan.dissipation`)
            visc = zeta_v * omega0 / omega if dashpot else zeta_v
            f[r, j] = omega / (2.0 * PI)
            zeta[r, j] = D / (2.0 * PI * k_eff * x**2) + visc
