"""Numba kernel of the swept-sine integrator with several exact Iwan joints (private; see
`jointcal.models.joints.integrate_joints`).

The scheme of `jointcal.models._integrator.run` (exact propagation of the stuck-joint linear
system, cubic Hermite input and remainders, one predict-evaluate-correct per step, reversals
located on the Hermite displacement), with one nonlinear remainder per joint: each joint has
its own DOF z_j = lz_j.x, turning-point stack and remainder r_j = F_iwan,j(z_j) - KT_j z_j, and
all the remainders of a step are corrected together. Exact Iwan joints only (no elements, no
sliders). The arithmetic is that of `run` in the same order, so one joint (or several of which
all but one are absent) gives `run`'s output bit for bit.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ._integrator import _hermite_tip
from ._masing import advance

__all__: list[str] = []


@njit(cache=True)
def run_joints(u, ud, maps, outputs, joints, y_out, z_out):
    """Integrate from rest; write the outputs y (n_y, N) and the joint displacements z (J, N).

    u, ud (N,): input and its rate.
    maps: (H, Gsub, Wub, Phi, Gf, lz, lv): as `run`, with Gf (J, n, 4) the substep's map of
    joint j's remainder Hermite data, lz, lv (J, n): z_j = lz[j].x, z_j' = lv[j].x.
    outputs: (cy (n_y, n), dyu (n_y,), dyf (n_y, J)): y = cy.x + dyu u + dyf.r.
    joints: (kind (J,) int64: 0 none, 1 exact Iwan; KT, R, chi, phimax, Fs (J,) with R and chi
    passed as R/(chi+1), chi+1).
    """
    H, Gsub, Wub, Phi, Gf, lz, lv = maps
    cy, dyu, dyf = outputs
    jkind, KT, R, chi, phimax, Fs = joints
    J = jkind.shape[0]
    n_y = cy.shape[0]
    n_sub = Gsub.shape[0]
    n = Phi.shape[0]
    x = np.zeros(n)
    xl = np.zeros(n)
    xp = np.zeros(n)
    x1 = np.zeros(n)
    su = np.zeros((J, 256))
    sF = np.zeros((J, 256))
    ns = np.zeros(J, dtype=np.int64)
    d = np.zeros(J, dtype=np.int64)
    r0 = np.zeros(J)
    rd0 = np.zeros(J)
    rp = np.zeros(J)
    r1 = np.zeros(J)
    rd1 = np.zeros(J)
    z0 = np.zeros(J)
    v0 = np.zeros(J)
    z1 = np.zeros(J)
    v1 = np.zeros(J)
    zp = np.zeros(J)
    Fj = np.zeros(J)
    Kd = np.zeros(J)
    have_prev = False
    h = H / n_sub
    N = u.shape[0]
    for o in range(n_y):
        y_out[o, 0] = dyu[o] * u[0]
    for jt in range(J):
        z_out[jt, 0] = 0.0
    for k in range(N - 1):
        p0 = u[k]
        p1 = H * ud[k]
        p2 = u[k + 1]
        p3 = H * ud[k + 1]
        for j in range(n_sub):
            for i in range(n):
                s = Gsub[j, i, 0] * p0 + Gsub[j, i, 1] * p1 + Gsub[j, i, 2] * p2 + Gsub[j, i, 3] * p3
                for jt in range(J):
                    s += Gf[jt, i, 0] * r0[jt] + Gf[jt, i, 1] * h * rd0[jt]
                for jj in range(n):
                    s += Phi[i, jj] * x[jj]
                xl[i] = s
            if ns.max() + 2 > su.shape[1]:  # room for the reversal this step may push
                su2 = np.zeros((J, 2 * su.shape[1]))
                sF2 = np.zeros((J, 2 * su.shape[1]))
                su2[:, : su.shape[1]] = su
                sF2[:, : su.shape[1]] = sF
                su = su2
                sF = sF2
            # predictor: each r_nl extrapolated by the quadratic through (r_prev, r0, rd0)
            for jt in range(J):
                if have_prev:
                    r1[jt] = r0[jt] + h * rd0[jt] + (r0[jt] - rp[jt] - h * rd0[jt])
                    rd1[jt] = rd0[jt] + 2.0 * (r0[jt] - rp[jt] - h * rd0[jt]) / h
                else:
                    r1[jt] = r0[jt] + h * rd0[jt]
                    rd1[jt] = rd0[jt]
            for i in range(n):
                s = xl[i]
                for jt in range(J):
                    s = s + Gf[jt, i, 2] * r1[jt]
                    s = s + Gf[jt, i, 3] * h * rd1[jt]
                xp[i] = s
            # evaluate each joint once, at the predicted motion, and commit its state
            for jt in range(J):
                zz = 0.0
                vv = 0.0
                for i in range(n):
                    zz += lz[jt, i] * xp[i]
                    vv += lv[jt, i] * xp[i]
                z1[jt] = zz
                v1[jt] = vv
                zp[jt] = zz
                Fj[jt] = 0.0
                Kd[jt] = 0.0
                if jkind[jt] != 0:
                    turn = False
                    zt = 0.0
                    dj = d[jt]
                    if dj != 0 and vv * dj < 0.0:
                        turn = True
                        zt = _hermite_tip(z0[jt], v0[jt], zz, vv, h, dj)
                    elif dj != 0 and dj * (zz - z0[jt]) < 0.0:
                        turn = True
                        zt = z0[jt]
                    F, K, nn, dd = advance(su[jt], sF[jt], ns[jt], dj, zz, zt, turn, KT[jt], R[jt], chi[jt],
                                           phimax[jt], Fs[jt])
                    ns[jt] = nn
                    d[jt] = dd
                    Fj[jt] = F - KT[jt] * zz
                    Kd[jt] = K - KT[jt]
            # correct the state with the evaluated remainders, then move each joint force to its
            # corrected displacement along its tangent (an O(h^4) shift: no second pow)
            for jt in range(J):
                r1[jt] = Fj[jt]
                rd1[jt] = Kd[jt] * v1[jt]
            for i in range(n):
                s = xl[i]
                for jt in range(J):
                    s = s + Gf[jt, i, 2] * r1[jt]
                    s = s + Gf[jt, i, 3] * h * rd1[jt]
                x1[i] = s
            for jt in range(J):
                zz = 0.0
                vv = 0.0
                for i in range(n):
                    zz += lz[jt, i] * x1[i]
                    vv += lv[jt, i] * x1[i]
                z1[jt] = zz
                v1[jt] = vv
                Fj[jt] += Kd[jt] * (zz - zp[jt])
                r1[jt] = Fj[jt]
                rd1[jt] = Kd[jt] * vv
            have_prev = True
            for i in range(n):
                x[i] = x1[i]
            for jt in range(J):
                rp[jt] = r0[jt]
                r0[jt] = r1[jt]
                rd0[jt] = rd1[jt]
                z0[jt] = z1[jt]
                v0[jt] = v1[jt]
        for o in range(n_y):
            s = dyu[o] * u[k + 1] + dyf[o, 0] * r0[0]
            for jt in range(1, J):
                s += dyf[o, jt] * r0[jt]
            for i in range(n):
                s += cy[o, i] * x[i]
            y_out[o, k + 1] = s
        for jt in range(J):
            z_out[jt, k + 1] = z0[jt]
