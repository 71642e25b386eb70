"""The voltage drive's coil in the rotating-frame mode: its RK4, forward sensitivities and pole.

Private: `jointcal.measure._sweep_problem.Problem` integrates a voltage-driven run with the
shaker's coil when a coil is given (`jointcal.measure.sweepfit.fit_swept_mode`'s ``coil``).

An amplifier voltage V drives the coil's current i, L i' + R i + Bl x' = V, whose force Bl i
drives the mode. With u = Bl i / m (in/s^2), w_e = R / L (rad/s, the coil's corner) and
g = Bl^2 / (m L) (1/s^2, the back-EMF gain), the mode and its coil are

    x'' + D x' + Omega^2 x = u,    u' = -w_e u - g x' + (w_e + i W_0) A(w) r,

the coil's equation linear in u; the forcing is scaled so that A(w) keeps the no-coil fit's
meaning at W_0 (a coil without back-EMF passes (w_e + i W_0) / (w_e + i w) of it). In the frame
rotating at W_0 (x_a = Z e^{i W_0 t}, u_a = U e^{i W_0 t}):

    Z'' = U - (2 i W_0 + c) Z' - (Omega^2 - W_0^2 + i (c W_0 + phi D Omega)) Z,
    U' = (w_e + i W_0) (A_0 R - i A_1 R' / W_0 - U) - g (Z' + i W_0 Z).

The read-out's pole is the root of (s + w_e)(s^2 + D s + Omega^2) + g s nearest i Omega
(`coil_pole`), the rig's pole as `jointcal.synth.rig_truth.rig_pole` defines it.

`coil_mode_sensitivity` integrates it by the RK4 steps of `jointcal.measure._rotating.rotating_mode`
(the same stages, U a third state) and differentiates each step as it is written, as
`jointcal.measure._rotating_sensitivity` does. Directions: 0-15 as there; 16, ln w_e; 17, g.
The coil's start U_0 is the forced state's, ((w_e + i W_0) F_0 - g (y_0 + i W_0 z_0)) / (w_e + i W_0 + nu),
F_0 the forcing at the start and nu = Z'/Z there (a constant of the passage).
"""
from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from ._rotating_sensitivity import _dacc_row, _mode_terms, _tangent_stage, _tangent_step

__all__ = ["coil_mode_sensitivity", "coil_pole", "N_COIL_DIRECTIONS"]

N_COIL_DIRECTIONS = 18


@numba.njit(cache=True, inline="always")
def _put_u(g, k, v):
    g[2, k], g[3, k] = v.real, v.imag


@numba.njit(cache=True, inline="always")
def _stage(z, y, u, r, rd, w0, p, q_ref, l_lo, l_hi, dirs, t, out, g):
    """Z'' and U' at (z, y, u), and in out (4, m: Re, Im of d Z'', then of d U') their derivatives along
    each direction given the stage's state derivatives t (6, m: Re, Im of dZ, dZ', dU); g: work, 4 x 18.
    The mode's own terms are the rotating kernel's (`_rotating_sensitivity._mode_terms`)."""
    stiff, visc, force, c00, c01, c10, c11 = _mode_terms(z, y, r, rd, w0, p, q_ref, l_lo, l_hi, g)
    we, gb = p[12], p[13]
    ew = we + 1j * w0
    a = u - visc * y - stiff * z
    b = ew * (force - u) - gb * (y + 1j * w0 * z)
    _put_u(g, 6, ew * r)
    _put_u(g, 7, 1j * ew * r)
    _put_u(g, 9, -1j * ew * rd / w0)
    _put_u(g, 10, ew * rd / w0)
    _put_u(g, 16, we * (force - u))
    _put_u(g, 17, -(y + 1j * w0 * z))
    for j in range(dirs.size):
        k = dirs[j]
        # d a = -stiff dZ - visc dZ' + f_l Re(conj(z) dZ) + dU
        out[0, j] = g[0, k] + c00 * t[0, j] + c01 * t[1, j] - visc.real * t[2, j] + visc.imag * t[3, j] + t[4, j]
        out[1, j] = g[1, k] + c10 * t[0, j] + c11 * t[1, j] - visc.imag * t[2, j] - visc.real * t[3, j] + t[5, j]
        # d b = -(w_e + i w0) dU - g (dZ' + i w0 dZ)
        out[2, j] = g[2, k] - we * t[4, j] + w0 * t[5, j] - gb * (t[2, j] - w0 * t[1, j])
        out[3, j] = g[3, k] - w0 * t[4, j] - we * t[5, j] - gb * (t[3, j] + w0 * t[0, j])
    return a, b


@numba.njit(cache=True)
def _start_u(z0, y0, nu, r0, rd0, w0, p, dirs, st):
    """The coil's forced start U_0 (module docstring), its derivatives written into st[4:6]."""
    we, gb = p[12], p[13]
    ew = we + 1j * w0
    den = ew + nu
    f0 = (p[6] + 1j * p[7]) * r0 - 1j * (p[9] + 1j * p[10]) * rd0 / w0
    u0 = (ew * f0 - gb * (y0 + 1j * w0 * z0)) / den
    for j in range(dirs.size):
        k = dirs[j]
        v = 0j
        if k == 6:
            v = ew * r0 / den
        elif k == 7:
            v = 1j * ew * r0 / den
        elif k == 9:
            v = -1j * ew * rd0 / w0 / den
        elif k == 10:
            v = ew * rd0 / w0 / den
        elif k == 12:
            v = -1j * gb * w0 / den
        elif k == 13:
            v = gb * w0 / den
        elif k == 14:
            v = -gb / den
        elif k == 15:
            v = -1j * gb / den
        elif k == 16:
            v = we * (f0 - u0) / den
        elif k == 17:
            v = -(y0 + 1j * w0 * z0) / den
        st[4, j], st[5, j] = v.real, v.imag
    return u0


@numba.njit(cache=True)
def coil_mode_sensitivity(r, rd, rm, rdm, w0, h, p, q_ref, l_lo, l_hi, z0, y0, nu, dirs, chain, rows):
    """RK4 of the mode and its coil in the frame rotating at w0, and its forward sensitivities.

    As `jointcal.measure._rotating_sensitivity.rotating_mode_sensitivity`, with p of shape (14,): p[12] the
    coil's corner w_e (rad/s), p[13] its back-EMF gain g (1/s^2); nu (complex, 1/s) Z'/Z at the start
    (the coil's forced start); dirs numbered as in the module docstring. With no dirs, the response alone.

    Returns
    -------
    Z, acc : ndarray of complex, shape (n,)
        The displacement envelope (in) and its acceleration envelope Z'' + 2 i w0 Z' - w0^2 Z (in/s^2).
    dacc : ndarray of complex, shape (k, c)
        d acc / d parameter at the steps `rows`.
    """
    n, m = r.size, dirs.size
    Z = np.empty(n, np.complex128)
    acc = np.empty(n, np.complex128)
    dacc = np.zeros((rows.size, chain.shape[1]), np.complex128)
    st = np.zeros((6, m))  # the state's derivatives: Re, Im of dZ, dZ', dU
    for j in range(m):
        if 12 <= dirs[j] <= 15:
            st[dirs[j] - 12, j] = 1.0
    u = _start_u(z0, y0, nu, r[0], rd[0], w0, p, dirs, st)
    d1, d2, d3, d4 = np.empty((4, m)), np.empty((4, m)), np.empty((4, m)), np.empty((4, m))
    t = np.empty((6, m))
    g = np.zeros((4, N_COIL_DIRECTIONS))
    z, y = z0, y0
    i_row = 0
    hh = 0.5 * h
    for k in range(n):
        a1, b1 = _stage(z, y, u, r[k], rd[k], w0, p, q_ref, l_lo, l_hi, dirs, st, d1, g)
        Z[k] = z
        acc[k] = a1 + 2j * w0 * y - w0 * w0 * z
        if i_row < rows.size and rows[i_row] == k:
            _dacc_row(dacc, i_row, chain, d1, st, w0)
            i_row += 1
        if k == n - 1:
            break
        _tangent_stage(t, st, d1, d1, hh, 0.0)
        a2, b2 = _stage(z + hh * y, y + hh * a1, u + hh * b1, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi, dirs, t, d2, g)
        _tangent_stage(t, st, d1, d2, hh, hh)
        a3, b3 = _stage(z + hh * (y + hh * a1), y + hh * a2, u + hh * b2, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi,
                        dirs, t, d3, g)
        _tangent_stage(t, st, d2, d3, h, hh)
        a4, b4 = _stage(z + h * (y + hh * a2), y + h * a3, u + h * b3, r[k + 1], rd[k + 1], w0, p, q_ref, l_lo, l_hi,
                        dirs, t, d4, g)
        _tangent_step(st, d1, d2, d3, d4, h)
        z = z + h * y + h * h / 6.0 * (a1 + a2 + a3)
        y = y + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        u = u + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
    return Z, acc, dacc


def coil_pole(omega2: NDArray, d: NDArray, w_e: float, g: float) -> tuple[NDArray, NDArray]:
    """The mode's pole with its coil: the root of (s + w_e)(s^2 + D s + Omega^2) + g s nearest i Omega.

    Parameters
    ----------
    omega2, d : array_like
        The mode's Omega^2 (rad^2/s^2) and D = 2 zeta Omega (1/s), any shape.
    w_e, g : float
        The coil's corner R / L (rad/s) and back-EMF gain Bl^2 / (m L) (1/s^2).

    Returns
    -------
    f_hz, zeta : ndarray
        |s| / 2 pi (Hz) and -Re(s) / |s|, the shape of omega2.
    """
    omega2, d = np.broadcast_arrays(np.asarray(omega2, float), np.asarray(d, float))
    f, z = np.empty(omega2.shape), np.empty(omega2.shape)
    for i in np.ndindex(omega2.shape):
        roots = np.roots([1.0, w_e + d[i], omega2[i] + d[i] * w_e + g, w_e * omega2[i]])
        roots = roots[roots.imag > 0]
        s = roots[np.argmin(np.abs(np.abs(roots) - np.sqrt(omega2[i])))] if roots.size else complex("nan")
        f[i], z[i] = abs(s) / (2 * np.pi), -s.real / abs(s)
    return f, z
