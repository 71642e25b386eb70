"""The rotating-frame mode's RK4 and its forward sensitivities: the sweep fit's exact Jacobian.

Private: `jointcal.measure._sweep_problem.Problem.jacobian` calls `rotating_mode_sensitivity`.
It integrates the same discrete model as `jointcal.measure._rotating.rotating_mode` (the same RK4
steps, the same operations in the same order, so Z and its acceleration envelope are the same
numbers) and, beside it, the derivative of each step with respect to the mode's coefficients and
its start state: the RK4 step differentiated as it is written (each stage's derivative by the
chain rule through the stages before it), so the derivatives are those of the discrete model,
exact to rounding, at any step size. The model is not holomorphic in Z (its coefficients depend
on q = |Z|), but each direction is a real parameter, so its derivative is one complex number per
state, and the amplitude's share is

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


@numba.njit(cache=True)
def _stage(z, y, r, rd, w0, p, q_ref, l_lo, l_hi, dirs, dz, dy, da, g):
    """The equation's right-hand side Z'' at (z, y), and in da its derivative along each direction given
    the stage's state derivatives (dz, dy): `_rotating._rhs` with its chain rule (g: work space, 16)."""
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
    a = force - visc * y - stiff * z
    gw = -(w2 + 0.5j * phi * d * sw) * z  # d a / d ln Omega^2
    gd = -d * ((1.0 - phi) * y + 1j * ((1.0 - phi) * w0 + phi * sw) * z)  # d a / d ln D
    # each direction's own term (the state's aside): ln p[0], ln p[1], p[2], ..., p[11]
    g[0], g[1], g[2], g[3], g[4], g[5] = gw, gd, gw * L, gw * L * L, gd * L, gd * L * L
    g[6], g[7], g[8] = r, 1j * r, d * y - 1j * d * (sw - w0) * z
    g[9], g[10], g[11] = -1j * rd / w0, rd / w0, gw * L * L * L
    # the amplitude's share: d a / d L times dL = Re(conj(z) dz) / |z|^2, zero where L is held
    f_l = (gw * (p[2] + 2.0 * p[3] * L + 3.0 * p[11] * L * L) + gd * (p[4] + 2.0 * p[5] * L)) / (az * az) \
        if inside else 0j
    zr, zi = z.real, z.imag
    for j in range(dirs.size):
        da[j] = g[dirs[j]] - stiff * dz[j] - visc * dy[j] + f_l * (zr * dz[j].real + zi * dz[j].imag)
    return a


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
    da = np.empty(m, np.complex128)
    dz, dy = np.zeros(m, np.complex128), np.zeros(m, np.complex128)
    for j in range(m):  # the start state's own directions
        dz[j] = 1.0 if dirs[j] == 12 else (1j if dirs[j] == 13 else 0j)
        dy[j] = 1.0 if dirs[j] == 14 else (1j if dirs[j] == 15 else 0j)
    d1, d2, d3, d4 = np.empty(m, np.complex128), np.empty(m, np.complex128), np.empty(m, np.complex128), \
        np.empty(m, np.complex128)
    sz, sy = np.empty(m, np.complex128), np.empty(m, np.complex128)
    g = np.zeros(N_DIRECTIONS, np.complex128)  # the start state's own terms stay 0
    z, y = z0, y0
    i_row = 0
    hh = 0.5 * h
    for k in range(n):
        a1 = _stage(z, y, r[k], rd[k], w0, p, q_ref, l_lo, l_hi, dirs, dz, dy, d1, g)
        Z[k] = z
        acc[k] = a1 + 2j * w0 * y - w0 * w0 * z
        if i_row < rows.size and rows[i_row] == k:
            for j in range(m):
                da[j] = d1[j] + 2j * w0 * dy[j] - w0 * w0 * dz[j]
            for i in range(chain.shape[1]):
                t = 0j
                for j in range(m):
                    t += chain[j, i] * da[j]
                dacc[i_row, i] = t
            i_row += 1
        if k == n - 1:
            break
        for j in range(m):
            sz[j], sy[j] = dz[j] + hh * dy[j], dy[j] + hh * d1[j]
        a2 = _stage(z + hh * y, y + hh * a1, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi, dirs, sz, sy, d2, g)
        for j in range(m):
            sz[j], sy[j] = dz[j] + hh * (dy[j] + hh * d1[j]), dy[j] + hh * d2[j]
        a3 = _stage(z + hh * (y + hh * a1), y + hh * a2, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi, dirs, sz, sy, d3, g)
        for j in range(m):
            sz[j], sy[j] = dz[j] + h * (dy[j] + hh * d2[j]), dy[j] + h * d3[j]
        a4 = _stage(z + h * (y + hh * a2), y + h * a3, r[k + 1], rd[k + 1], w0, p, q_ref, l_lo, l_hi, dirs, sz, sy,
                    d4, g)
        for j in range(m):
            dz[j] = dz[j] + h * dy[j] + h * h / 6.0 * (d1[j] + d2[j] + d3[j])
            dy[j] = dy[j] + h / 6.0 * (d1[j] + 2.0 * d2[j] + 2.0 * d3[j] + d4[j])
        z = z + h * y + h * h / 6.0 * (a1 + a2 + a3)
        y = y + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return Z, acc, dacc
