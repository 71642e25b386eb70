"""Numba kernel of the swept-sine integrator (private; see `jointcal.models.simulate`).

Exponential integrator: the linear system with the joint stuck is propagated exactly
over each step (x1 = Phi x0 + ...), so the linear natural frequencies carry no
discretisation error at any step. The base acceleration u(t) and the nonlinear
remainder r_nl(t) enter as cubic Hermite polynomials over the step (values and rates
at both ends), integrated exactly against the propagator. r_nl at the step's end is
found by predict-evaluate-correct: the joint is evaluated (and its turning-point
state committed) once per step at the predicted motion, and its force is carried to
the corrected displacement along the branch tangent; a reversal of the joint motion inside a
step is located on the Hermite displacement so hysteresis loops keep their true tips.

One kernel serves one joint (`jointcal.models.simulate.integrate`) and several
(`jointcal.models.joints.integrate_joints`, e.g. two jointed modes on a shaker): each joint
has its own DOF z_j = lz_j.x, turning-point stack and remainder r_j = F_j(z_j) - KT_j z_j,
and all the remainders of a step are predicted and corrected together.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from numba.cpython.unsafe.tuple import tuple_setitem as _put  # a tuple with one item replaced

from ._masing import advance

__all__: list[str] = []


@njit(cache=True, inline="always")
def _hermite_tip(z0, v0, z1, v1, h, d):
    """Extremum of the cubic Hermite z(tau) on a step where z' changes sign."""
    a = h * v0
    b = h * v1
    c2 = 3.0 * (z1 - z0) - 2.0 * a - b
    c3 = 2.0 * (z0 - z1) + a + b
    tau = a / (a - b)  # linear fallback
    if abs(c3) > 1e-14 * (abs(c2) + abs(a) + 1e-300):
        disc = 4.0 * c2 * c2 - 12.0 * c3 * a
        if disc >= 0.0:
            sq = np.sqrt(disc)
            t1 = (-2.0 * c2 + sq) / (6.0 * c3)
            t2 = (-2.0 * c2 - sq) / (6.0 * c3)
            if 0.0 <= t1 <= 1.0:
                tau = t1
            elif 0.0 <= t2 <= 1.0:
                tau = t2
    elif abs(c2) > 0.0:
        t = -a / (2.0 * c2)
        if 0.0 <= t <= 1.0:
            tau = t
    zt = z0 + tau * (a + tau * (c2 + tau * c3))
    # the tip lies at least as far along d as both ends
    return d * max(d * zt, d * z0, d * z1)


@njit(cache=True)
def rate(u, fs):
    """Time derivative of a sampled signal: 4th-order central differences, 3rd-order at the ends."""
    N = u.shape[0]
    ud = np.empty(N)
    if N < 5:
        for i in range(N):
            lo = max(i - 1, 0)
            hi = min(i + 1, N - 1)
            ud[i] = (u[hi] - u[lo]) * fs / max(hi - lo, 1)
        return ud
    c = fs / 12.0
    for i in range(2, N - 2):
        ud[i] = (u[i - 2] - 8.0 * u[i - 1] + 8.0 * u[i + 1] - u[i + 2]) * c
    c = fs / 6.0
    for i in range(2):
        ud[i] = (-11.0 * u[i] + 18.0 * u[i + 1] - 9.0 * u[i + 2] + 2.0 * u[i + 3]) * c
        j = N - 1 - i
        ud[j] = (11.0 * u[j] - 18.0 * u[j - 1] + 9.0 * u[j - 2] - 2.0 * u[j - 3]) * c
    return ud


@njit(cache=True, inline="always")
def _element(code, a, b, z, v):
    """Force of one element of the table (`jointcal.models.elements`) at z (in), z' (in/s).

    Returns (force, dforce/dz, dforce/dz'). A new kind of element is one branch here.
    """
    if code == 1:  # cubic spring a z^3
        return a * z * z * z, 3.0 * a * z * z, 0.0
    if code == 2:  # contact spring a max(z - b, 0)
        if z > b:
            return a * (z - b), a, 0.0
        return 0.0, 0.0, 0.0
    if code == 3:  # quadratic damper a z'|z'|
        return a * v * abs(v), 0.0, 2.0 * a * abs(v)
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _backbone(z, KT, R1, e, phimax, Fs):
    """The exact Iwan joint's virgin backbone at z (in) and its tangent (R1 = R/(chi+1), e = chi+1)."""
    a = abs(z)
    if a >= phimax:
        return (Fs if z > 0.0 else -Fs), 0.0
    F = KT * a - R1 * a ** (e + 1.0) / (e + 1.0)
    return (F if z >= 0.0 else -F), KT - R1 * a**e


@njit(cache=True, inline="always")
def _plus_remainders(xl, Gf, r, rd, h, i):
    """xl[i] + the state's response to the remainders' end data: sum_j Gf[j, i, 2] r_j + Gf[j, i, 3] h r_j'."""
    s = xl[i]
    for jt in range(len(r)):
        s = s + Gf[jt, i, 2] * r[jt]
        s = s + Gf[jt, i, 3] * h * rd[jt]
    return s


@njit(cache=True, inline="always")
def _corrected(xl, Gf, r, rd, h, lz, lv, xe, z):
    """The state xe at the substep's end given the remainders' end data (written into xe), and each joint's
    (z_j, z_j') = (lz[j].xe, lv[j].xe) as tuples of the shape of `z`."""
    for i in range(xl.shape[0]):
        xe[i] = _plus_remainders(xl, Gf, r, rd, h, i)
    v = z
    for jt in range(len(z)):
        zz = 0.0
        vv = 0.0
        for i in range(xe.shape[0]):
            zz += lz[jt, i] * xe[i]
            vv += lv[jt, i] * xe[i]
        z = _put(z, jt, zz)
        v = _put(v, jt, vv)
    return z, v


@njit(cache=True)
def run(u, ud, maps, outputs, joints, sliders, elements, y_out, z_out):
    """Integrate from rest; write the outputs y (n_y, N) and the joint displacements z (J, N).

    u, ud (N,): input and its rate.
    maps: (H, Gsub, Wub, Phi, Gf, lz, lv, az, bzu, bzf): sample interval H; Gsub[j] (n, 4)
    maps the parent interval's Hermite data [u_k, H u'_k, u_k+1, H u'_k+1] to the input's
    contribution over substep j, Wub[j] (4,) gives u at the substep's end; Phi (n, n) the
    substep's propagator and Gf (J, n, 4) its map of joint j's remainder Hermite data;
    z_j = lz[j].x, z_j' = lv[j].x (lz, lv (J, n)); the first joint's z'' = az.x + bzu u + bzf.r
    (az (n,), bzf (J,)).
    outputs: (cy (n_y, n), dyu (n_y,), dyf (n_y, J)): y = cy.x + dyu u + dyf.r.
    joints: (kind, KT, R, chi, phimax, Fs), each a tuple of J values: kind 0 none, 1 exact Iwan (R and
    chi passed as R/(chi+1), chi+1), 2 Jenkins sliders (a test reference; KT = sum of their stiffnesses;
    at most one joint). Tuples, as the per-joint state below: the number of joints is known when the
    kernel compiles and the joints' parameters and state stay in registers (one joint: within about 5%
    of the CPU time of the former one-joint kernel, measured on a loaded machine).
    sliders: (sk, sphi), the sliders' stiffnesses and slip displacements.
    elements: (codes (n_e,), coefs (n_e, 2)), the element table sorted by code, acting on the
    first joint's DOF z_0. Code 4 (a backbone share s, exact Iwan joint only) replaces the share
    s of the joint's hysteretic force by the elastic force along its virgin backbone:
    F = (1 - s) F_iwan(history) + s F_b(z).
    """
    H, Gsub, Wub, Phi, Gf, lz, lv, az, bzu, bzf = maps
    cy, dyu, dyf = outputs
    jkind, KT, R, chi, phimax, Fs = joints
    sk, sphi = sliders
    codes, coefs = elements
    J = len(KT)
    n_el = codes.shape[0]
    n_y = cy.shape[0]
    n_sub = Gsub.shape[0]
    n = Phi.shape[0]
    x = np.zeros(n)
    xl = np.zeros(n)
    xp = np.zeros(n)
    x1 = np.zeros(n)
    su = np.zeros((J, 256))  # each joint's turning points
    sF = np.zeros((J, 256))
    top = 0  # the deepest stack yet
    sx = np.zeros(sk.shape[0])  # slider anchors
    # per joint: remainder and rate at the step's start (r0, rd0), the step before (rp), its end (r1, rd1);
    # displacement and rate at the start (z0, v0) and end (z1, v1), predicted (zp); force and tangent shift
    zero = KT
    for jt in range(J):
        zero = _put(zero, jt, 0.0)
    r0 = rd0 = rp = r1 = rd1 = z0 = v0 = z1 = v1 = zp = Fj = Kd = zero
    izero = jkind
    for jt in range(J):
        izero = _put(izero, jt, 0)
    ns = d = izero  # each joint's stack depth and direction of motion
    Fiw = 0.0  # the first joint's Iwan force and tangent, for a backbone share
    Kiw = 0.0
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
            if top + 2 > su.shape[1]:  # room for the reversal this step may push
                su2 = np.zeros((J, 2 * su.shape[1]))
                sF2 = np.zeros((J, 2 * su.shape[1]))
                su2[:, : su.shape[1]] = su
                sF2[:, : su.shape[1]] = sF
                su = su2
                sF = sF2
            # predictor: each r_nl extrapolated by the quadratic through (r_prev, r0, rd0)
            for jt in range(J):
                if have_prev:
                    r1 = _put(r1, jt, r0[jt] + h * rd0[jt] + (r0[jt] - rp[jt] - h * rd0[jt]))
                    rd1 = _put(rd1, jt, rd0[jt] + 2.0 * (r0[jt] - rp[jt] - h * rd0[jt]) / h)
                else:
                    r1 = _put(r1, jt, r0[jt] + h * rd0[jt])
                    rd1 = _put(rd1, jt, rd0[jt])
            z1, v1 = _corrected(xl, Gf, r1, rd1, h, lz, lv, xp, z1)
            zp = z1
            # evaluate each joint once, at the predicted motion, and commit its state
            for jt in range(J):
                zz = z1[jt]
                vv = v1[jt]
                F = 0.0
                K = KT[jt]  # no joint: no remainder, no tangent shift
                dj = d[jt]
                turn = False
                zt = 0.0
                if jkind[jt] != 0:
                    if dj != 0 and vv * dj < 0.0:
                        turn = True
                        zt = _hermite_tip(z0[jt], v0[jt], zz, vv, h, dj)
                    elif dj != 0 and dj * (zz - z0[jt]) < 0.0:
                        turn = True
                        zt = z0[jt]
                if jkind[jt] == 1:
                    F, K, nn, dd = advance(su[jt], sF[jt], ns[jt], dj, zz, zt, turn, KT[jt], R[jt], chi[jt],
                                           phimax[jt], Fs[jt])
                    ns = _put(ns, jt, nn)
                    d = _put(d, jt, dd)
                    top = max(top, nn)
                    if jt == 0:
                        Fiw = F
                        Kiw = K
                elif jkind[jt] == 2:
                    K = 0.0
                    for i in range(sk.shape[0]):
                        xi = sx[i]
                        if turn:
                            xi = min(max(xi, zt - sphi[i]), zt + sphi[i])
                        if xi < zz - sphi[i]:  # slipping: anchor dragged along
                            xi = zz - sphi[i]
                        elif xi > zz + sphi[i]:
                            xi = zz + sphi[i]
                        else:  # stuck: contributes its stiffness to the tangent
                            K += sk[i]
                        sx[i] = xi
                        F += sk[i] * (zz - xi)
                    if turn:
                        d = _put(d, jt, -dj)
                    elif dj == 0 and zz != 0.0:
                        d = _put(d, jt, 1 if zz > 0.0 else -1)
                Fj = _put(Fj, jt, F - KT[jt] * zz if jkind[jt] != 0 else 0.0)
                Kd = _put(Kd, jt, K - KT[jt] if jkind[jt] != 0 else 0.0)
            for sweep in range(2):
                r1 = Fj
                for jt in range(J):
                    rd1 = _put(rd1, jt, Kd[jt] * v1[jt])
                r10 = r1[0]
                rd10 = rd1[0]
                cv = 0.0
                for e in range(n_el):  # the elements, on the first joint's DOF
                    if codes[e] == 4:  # backbone share: -s (F_iwan - F_b), F_iwan moved along its tangent
                        fb, kb = _backbone(z1[0], KT[0], R[0], chi[0], phimax[0], Fs[0])
                        r10 -= coefs[e, 0] * (Fiw + Kiw * (z1[0] - zp[0]) - fb)
                        rd10 -= coefs[e, 0] * (Kiw - kb) * v1[0]
                        continue
                    fe, kz, ce = _element(codes[e], coefs[e, 0], coefs[e, 1], z1[0], v1[0])
                    r10 += fe
                    rd10 += kz * v1[0]
                    cv += ce
                r1 = _put(r1, 0, r10)
                if cv != 0.0:  # a damper: its rate needs z'' at the step's end, from the total r_nl
                    ub = Wub[j, 0] * p0 + Wub[j, 1] * p1 + Wub[j, 2] * p2 + Wub[j, 3] * p3
                    zdd = bzu * ub + bzf[0] * r1[0]
                    for jt in range(1, J):
                        zdd += bzf[jt] * r1[jt]
                    rd1 = _put(rd1, 0, rd10)
                    for i in range(n):
                        zdd += az[i] * _plus_remainders(xl, Gf, r1, rd1, h, i)
                    rd10 += cv * zdd
                rd1 = _put(rd1, 0, rd10)
                if sweep == 1:
                    break
                # correct the state with the evaluated remainders, then move each joint force to its
                # corrected displacement along its tangent (an O(h^4) shift: no second pow)
                z1, v1 = _corrected(xl, Gf, r1, rd1, h, lz, lv, x1, z1)
                for jt in range(J):
                    Fj = _put(Fj, jt, Fj[jt] + Kd[jt] * (z1[jt] - zp[jt]))
            have_prev = True
            for i in range(n):
                x[i] = x1[i]
            rp = r0
            r0 = r1
            rd0 = rd1
            z0 = z1
            v0 = v1
        for o in range(n_y):
            s = dyu[o] * u[k + 1] + dyf[o, 0] * r0[0]
            for jt in range(1, J):
                s += dyf[o, jt] * r0[jt]
            for i in range(n):
                s += cy[o, i] * x[i]
            y_out[o, k + 1] = s
        for jt in range(J):
            z_out[jt, k + 1] = z0[jt]
