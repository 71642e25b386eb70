"""Numba kernels: the four-parameter Iwan force by Masing/Madelung turning-point rules.

The parallel-series Iwan element obeys Masing's rules exactly, so its force for any
displacement history follows from the virgin backbone F_b and a stack of reversal
points (u_r, F_r):

* virgin loading (empty stack):      F = F_b(u)
* branch from the last reversal:     F = F_r + 2 F_b((u - u_r) / 2)
* crossing the previous reversal closes that hysteresis loop and erases it;
* a branch from the first reversal rejoins the virgin curve at -u_1.

No sliders are discretised: the force is exact for the power-law density (3.3).
These kernels are private; `jointcal.models.iwan` is the public surface.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__: list[str] = []


@njit(cache=True, inline="always")
def backbone(x, KT, R, chi, phimax, Fs):
    """Odd virgin backbone F_b(x) (lbf) and its tangent dF_b/dx (lbf/in).

    For speed the kernels pass R1 = R/(chi+1) as ``R`` and e = chi+1 as ``chi``
    (see `kernel_constants`): F_b = KT a - R1 a^(e+1)/(e+1), dF_b/da = KT - R1 a^e.
    """
    a = abs(x)
    if a >= phimax:
        F = Fs
        K = 0.0
    else:
        p = R * a ** chi
        F = KT * a - a * p / (chi + 1.0)
        K = KT - p
    if x < 0.0:
        F = -F
    return F, K


def kernel_constants(R, chi):
    """(R/(chi+1), chi+1): the density constants in the form the kernels take."""
    return float(R) / (chi + 1.0), chi + 1.0


@njit(cache=True, inline="always")
def _segment(su, sF, n, d, z_to, KT, R, chi, phimax, Fs):
    """Move along direction d to z_to, closing loops; return (n, F, K_tan)."""
    while n > 0:
        if n >= 2:
            if d * (z_to - su[n - 2]) >= 0.0:  # loop (r_{n-1}, r_n) closes
                n -= 2
                continue
        elif d * (z_to + su[0]) >= 0.0:  # rejoin the virgin curve at -u_1
            n = 0
        break
    if n == 0:
        return n, *backbone(z_to, KT, R, chi, phimax, Fs)
    Fb, K = backbone(0.5 * (z_to - su[n - 1]), KT, R, chi, phimax, Fs)
    return n, sF[n - 1] + 2.0 * Fb, K


@njit(cache=True, inline="always")
def advance(su, sF, n, d, z_to, z_turn, has_turn, KT, R, chi, phimax, Fs):
    """Advance the Iwan state to z_to, optionally through a reversal at z_turn.

    Mutates the stack in place (it must have room for one push, ``len(su) > n``) and
    returns ``(F, K_tan, n, d)``: force (lbf), tangent (lbf/in), stack depth, direction.
    """
    if has_turn:
        if d == 0:  # first motion ends in a reversal
            d = 1 if z_turn > 0.0 else -1
            Fz, K = backbone(z_turn, KT, R, chi, phimax, Fs)
        else:
            n, Fz, K = _segment(su, sF, n, d, z_turn, KT, R, chi, phimax, Fs)
        su[n] = z_turn
        sF[n] = Fz
        n += 1
        d = -d
    elif d == 0:
        if z_to == 0.0:
            return 0.0, KT, n, d
        d = 1 if z_to > 0.0 else -1
    n, F, K = _segment(su, sF, n, d, z_to, KT, R, chi, phimax, Fs)
    return F, K, n, d


@njit(cache=True)
def grow(su, sF, n):
    """Return the stack arrays with room for at least two more reversals."""
    if n + 2 <= su.shape[0]:
        return su, sF
    m = 2 * su.shape[0] + 4
    su2 = np.zeros(m)
    sF2 = np.zeros(m)
    su2[: su.shape[0]] = su
    sF2[: sF.shape[0]] = sF
    return su2, sF2


@njit(cache=True)
def force_history(u, KT, R, chi, phimax, Fs):
    """Iwan force (lbf) and tangent stiffness (lbf/in) along a displacement history u (in).

    Reversals are taken at the samples where the direction of motion changes.
    """
    N = u.shape[0]
    F = np.empty(N)
    K = np.empty(N)
    su = np.zeros(16)
    sF = np.zeros(16)
    n = 0
    d = 0
    z_prev = 0.0
    for i in range(N):
        su, sF = grow(su, sF, n)
        z = u[i]
        step = z - z_prev
        turn = d != 0 and d * step < 0.0
        if step == 0.0 and d != 0:
            # no motion: force unchanged
            F[i] = F[i - 1] if i > 0 else 0.0
            K[i] = K[i - 1] if i > 0 else KT
            continue
        Fi, Ki, n, d = advance(su, sF, n, d, z, z_prev, turn, KT, R, chi, phimax, Fs)
        F[i] = Fi
        K[i] = Ki
        z_prev = z
    return F, K
