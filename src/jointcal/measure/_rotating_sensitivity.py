"""The rotating-frame mode's RK4 and its forward sensitivities: the sweep fit's exact Jacobian.

Private: `jointcal.measure._sweep_problem.Problem.misfit` calls `rotating_mode_sensitivity` and keeps the
Jacobian for `Problem.jacobian_matrix`.
It integrates the same discrete model as `jointcal.measure._rotating.rotating_mode` (the same RK4
steps, the same operations in the same order, so Z and its acceleration envelope are the same
numbers) and, beside it, the derivative of each step with respect to the mode's coefficients and
its start state: the RK4 step differentiated as it is written (each stage's derivative by the
chain rule through the stages before it), so the derivatives are those of the discrete model,
exact to rounding, at any step size. The model is not holomorphic in Z (its coefficients depend
on q = |Z|), but each direction is a real parameter, so its derivative is one complex number per
state (carried as its real and imaginary parts: a 2 x 4 real map per stage), and the amplitude's
share is

    dL = Re(conj(Z) dZ) / |Z|^2,    L = ln(|Z| / q_ref),

zero where L is held at its limits [L_lo, L_hi].

Directions (`dirs`): 0 and 1, ln p[0] and ln p[1] (ln Omega_ref^2 and ln D_ref); 2-11, p[2]-p[11]
as they are (p[8] phi, p[6:8] and p[9:11] the modal constant and its slope, (in/s^2) per
reference unit); 12-15, Re z0, Im z0 (in), Re y0, Im y0 (in/s).
"""
from __future__ import annotations

import numba
import numpy as np

__all__ = ["rotating_mode_sensitivity", "N_DIRECTIONS"]

N_DIRECTIONS = 16


@numba.njit(cache=True, inline="always")
def _put(g, k, v):
    g[0, k], g[1, k] = v.real, v.imag


@numba.njit(cache=True, inline="always")
def _mode_terms(z, y, r, rd, w0, p, q_ref, l_lo, l_hi, g):
    """The mode's own terms at (z, y), shared with the coil's kernel (`jointcal.measure._coil`): the
    stiffness and viscous coefficients of Z'' = force - visc Z' - stiff Z, the drive's force, the directions'
    own terms of the mode's coefficients (ln p[0], ln p[1], p[2]-p[5], p[8], p[11]) written into g[0:2], and
    the real 2 x 2 map (c00, c01, c10, c11) of d Z'' on (Re dZ, Im dZ) with the amplitude's share."""
    az = abs(z)
    L = np.log(max(az, 1e-300) / q_ref)
    inside = l_lo < L < l_hi and az > 0.0
    L = min(max(L, l_lo), l_hi)
    w2 = p[0] * np.exp(p[2] * L + p[3] * L * L + p[11] * L * L * L)
    d = p[1] * np.exp(p[4] * L + p[5] * L * L)  # 2 zeta Omega at q
    phi = p[8]
    c = (1.0 - phi) * d
    sw = np.sqrt(w2)
    stiff = w2 - w0 * w0 + 1j * (c * w0 + phi * d * sw)
    visc = 2j * w0 + c
    force = (p[6] + 1j * p[7]) * r - 1j * (p[9] + 1j * p[10]) * rd / w0  # A(w) r_a in the frame
    gw = -(w2 + 0.5j * phi * d * sw) * z  # d a / d ln Omega^2
    gd = -d * ((1.0 - phi) * y + 1j * ((1.0 - phi) * w0 + phi * sw) * z)  # d a / d ln D
    # each direction's own term (the state's aside): ln p[0], ln p[1], p[2], ..., p[5], p[8], p[11]
    _put(g, 0, gw)
    _put(g, 1, gd)
    _put(g, 2, gw * L)
    _put(g, 3, gw * L * L)
    _put(g, 4, gd * L)
    _put(g, 5, gd * L * L)
    _put(g, 8, d * y - 1j * d * (sw - w0) * z)
    _put(g, 11, gw * L * L * L)
    # the amplitude's share: d a / d L times dL = Re(conj(z) dz) / |z|^2, zero where L is held
    f_l = (gw * (p[2] + 2.0 * p[3] * L + 3.0 * p[11] * L * L) + gd * (p[4] + 2.0 * p[5] * L)) / (az * az) \
        if inside else 0j
    # d a = -stiff dZ - visc dZ' + f_l Re(conj(z) dZ), as real 2 x 4 coefficients
    c00, c01 = -stiff.real + f_l.real * z.real, stiff.imag + f_l.real * z.imag
    c10, c11 = -stiff.imag + f_l.imag * z.real, -stiff.real + f_l.imag * z.imag
    return stiff, visc, force, c00, c01, c10, c11


@numba.njit(cache=True, inline="always")
def _stage(z, y, r, rd, w0, p, q_ref, l_lo, l_hi, dirs, t, out, g):
    """The equation's right-hand side Z'' at (z, y), and in out (2, m: real and imaginary parts) its derivative
    along each direction given the stage's state derivatives t (4, m: Re dZ, Im dZ, Re dZ', Im dZ'):
    `_rotating._rhs` with its chain rule (g: work space, 2 x 16)."""
    stiff, visc, force, c00, c01, c10, c11 = _mode_terms(z, y, r, rd, w0, p, q_ref, l_lo, l_hi, g)
    a = force - visc * y - stiff * z
    _put(g, 6, r)
    _put(g, 7, 1j * r)
    _put(g, 9, -1j * rd / w0)
    _put(g, 10, rd / w0)
    for j in range(dirs.size):
        out[0, j], out[1, j] = g[0, dirs[j]], g[1, dirs[j]]
    for j in range(dirs.size):
        out[0, j] += c00 * t[0, j] + c01 * t[1, j] - visc.real * t[2, j] + visc.imag * t[3, j]
        out[1, j] += c10 * t[0, j] + c11 * t[1, j] - visc.imag * t[2, j] - visc.real * t[3, j]
    return a


@numba.njit(cache=True, inline="always")
def _dacc_row(dacc, i_row, chain, d1, st, w0):
    """Row i_row of d acc / d parameter: d acc = d Z'' + 2 i w0 dZ' - w0^2 dZ along the chain's combinations."""
    for i in range(chain.shape[1]):
        t_re, t_im = 0.0, 0.0
        for j in range(chain.shape[0]):
            t_re += chain[j, i] * (d1[0, j] - 2.0 * w0 * st[3, j] - w0 * w0 * st[0, j])
            t_im += chain[j, i] * (d1[1, j] + 2.0 * w0 * st[2, j] - w0 * w0 * st[1, j])
        dacc[i_row, i] = t_re + 1j * t_im


@numba.njit(cache=True, inline="always")
def _tangent_stage(t, st, dp, dv, c, e):
    """The state derivatives at an RK4 stage, into t: dZ + c (dZ' + e dp), dZ' + c dv, and any first-order
    rows past the fourth (the coil's dU) + c times dv's rows past the second."""
    for q in range(2):
        for j in range(st.shape[1]):
            t[q, j] = st[q, j] + c * (st[q + 2, j] + e * dp[q, j])
            t[q + 2, j] = st[q + 2, j] + c * dv[q, j]
    for q in range(4, st.shape[0]):
        for j in range(st.shape[1]):
            t[q, j] = st[q, j] + c * dv[q - 2, j]


@numba.njit(cache=True, inline="always")
def _tangent_step(st, d1, d2, d3, d4, h):
    """The state derivatives' RK4 step, in place (the same weights as the state's own step)."""
    for q in range(2):
        for j in range(st.shape[1]):
            st[q, j] = st[q, j] + h * st[q + 2, j] + h * h / 6.0 * (d1[q, j] + d2[q, j] + d3[q, j])
            st[q + 2, j] = st[q + 2, j] + h / 6.0 * (d1[q, j] + 2.0 * d2[q, j] + 2.0 * d3[q, j] + d4[q, j])
    for q in range(4, st.shape[0]):
        for j in range(st.shape[1]):
            st[q, j] = st[q, j] + h / 6.0 * (d1[q - 2, j] + 2.0 * d2[q - 2, j] + 2.0 * d3[q - 2, j] + d4[q - 2, j])


@numba.njit(cache=True)
def rotating_mode_sensitivity(r, rd, rm, rdm, w0, h, p, q_ref, l_lo, l_hi, z0, y0, dirs, chain, rows):
    """RK4 of the mode in the frame rotating at w0 from (Z, Z') = (z0, y0), and its forward sensitivities.

    Parameters
    ----------
    r, rd : ndarray of complex, shape (n,)
        The drive's envelope and its rate at the steps; rm, rdm (shape (n - 1,)) at the midpoints.
    w0, h : float
        The frame's frequency (rad/s) and the step (s).
    p : ndarray, shape (12,)
        The mode's coefficients (`jointcal.measure._rotating.rotating_mode`'s p).
    q_ref, l_lo, l_hi : float
        The reference amplitude (in) and the limits of L = ln(q / q_ref).
    z0, y0 : complex
        The start state: Z (in) and Z' (in/s).
    dirs : ndarray of int64, shape (m,)
        The directions differentiated along (the module docstring's numbering).
    chain : ndarray, shape (m, c)
        The derivatives returned are along the c combinations of the directions chain[:, i] (the
        caller's parameters: d direction / d parameter).
    rows : ndarray of int64, shape (k,)
        Increasing steps at which the derivatives are returned.

    Returns
    -------
    Z : ndarray of complex, shape (n,)
        The displacement envelope, in.
    acc : ndarray of complex, shape (n,)
        Its acceleration envelope Z'' + 2 i w0 Z' - w0^2 Z, in/s^2.
    dacc : ndarray of complex, shape (k, c)
        d acc / d parameter at the steps `rows`.
    """
    n, m = r.size, dirs.size
    Z = np.empty(n, np.complex128)
    acc = np.empty(n, np.complex128)
    dacc = np.zeros((rows.size, chain.shape[1]), np.complex128)
    st = np.zeros((4, m))  # the state's derivatives: Re dZ, Im dZ, Re dZ', Im dZ'
    for j in range(m):  # the start state's own directions
        if dirs[j] >= 12:
            st[dirs[j] - 12, j] = 1.0
    d1, d2, d3, d4 = np.empty((2, m)), np.empty((2, m)), np.empty((2, m)), np.empty((2, m))
    t = np.empty((4, m))
    g = np.zeros((2, N_DIRECTIONS))  # the start state's own terms stay 0
    z, y = z0, y0
    i_row = 0
    hh = 0.5 * h
    for k in range(n):
        a1 = _stage(z, y, r[k], rd[k], w0, p, q_ref, l_lo, l_hi, dirs, st, d1, g)
        Z[k] = z
        acc[k] = a1 + 2j * w0 * y - w0 * w0 * z
        if i_row < rows.size and rows[i_row] == k:
            _dacc_row(dacc, i_row, chain, d1, st, w0)
            i_row += 1
        if k == n - 1:
            break
        _tangent_stage(t, st, d1, d1, hh, 0.0)
        a2 = _stage(z + hh * y, y + hh * a1, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi, dirs, t, d2, g)
        _tangent_stage(t, st, d1, d2, hh, hh)
        a3 = _stage(z + hh * (y + hh * a1), y + hh * a2, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi, dirs, t, d3, g)
        _tangent_stage(t, st, d2, d3, h, hh)
        a4 = _stage(z + h * (y + hh * a2), y + h * a3, r[k + 1], rd[k + 1], w0, p, q_ref, l_lo, l_hi, dirs, t, d4, g)
        _tangent_step(st, d1, d2, d3, d4, h)
        z = z + h * y + h * h / 6.0 * (a1 + a2 + a3)
        y = y + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return Z, acc, dacc
