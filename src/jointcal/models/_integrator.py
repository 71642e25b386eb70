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
"""
from __future__ import annotations

import numpy as np
from numba import njit

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


@njit(cache=True)
def run(u, ud, maps, outputs, joint, sliders, elements, y_out, z_out):
    """Integrate from rest; write the outputs y and the joint displacement z per input sample.

    u, ud (N,): input and its rate; y_out (n_y, N), z_out (N,).
    maps: (H, Gsub, Wub, Phi, Gf, lz, lv, az, bzu, bzf): sample interval H; Gsub[j] (n, 4)
    maps the parent interval's Hermite data [u_k, H u'_k, u_k+1, H u'_k+1] to the input's
    contribution over substep j, Wub[j] (4,) gives u at the substep's end; Phi, Gf the
    substep's propagator and its map of the r_nl Hermite data; z = lz.x, z' = lv.x,
    z'' = az.x + bzu u + bzf r_nl.
    outputs: (cy (n_y, n), dyu (n_y,), dyf (n_y,)): y = cy.x + dyu u + dyf r_nl.
    joint: (kind, KT, R, chi, phimax, Fs): kind 0 none, 1 exact Iwan (R and chi passed as
    R/(chi+1), chi+1), 2 Jenkins sliders (a test reference; KT = sum of their stiffnesses).
    sliders: (sk, sphi), the sliders' stiffnesses and slip displacements.
    elements: (codes (n_e,), coefs (n_e, 2)), the element table sorted by code. Code 4 (a backbone
    share s, exact Iwan joint only) replaces the share s of the joint's hysteretic force by the
    elastic force along its virgin backbone: F = (1 - s) F_iwan(history) + s F_b(z).
    """
    H, Gsub, Wub, Phi, Gf, lz, lv, az, bzu, bzf = maps
    cy, dyu, dyf = outputs
    jkind, KT, R, chi, phimax, Fs = joint
    sk, sphi = sliders
    codes, coefs = elements
    n_el = codes.shape[0]
    n_y = cy.shape[0]
    n_sub = Gsub.shape[0]
    n = Phi.shape[0]
    x = np.zeros(n)
    xl = np.zeros(n)
    x1 = np.zeros(n)
    su = np.zeros(256)
    sF = np.zeros(256)
    ns = 0
    d = 0
    sx = np.zeros(sk.shape[0])  # slider anchors
    r0 = 0.0
    rd0 = 0.0
    z0 = 0.0
    v0 = 0.0
    z1 = 0.0
    v1 = 0.0
    rp = 0.0
    have_prev = False
    h = H / n_sub
    N = u.shape[0]
    for o in range(n_y):
        y_out[o, 0] = dyu[o] * u[0]
    z_out[0] = 0.0
    for k in range(N - 1):
        p0 = u[k]
        p1 = H * ud[k]
        p2 = u[k + 1]
        p3 = H * ud[k + 1]
        for j in range(n_sub):
            for i in range(n):
                s = Gsub[j, i, 0] * p0 + Gsub[j, i, 1] * p1 + Gsub[j, i, 2] * p2 + Gsub[j, i, 3] * p3
                s += Gf[i, 0] * r0 + Gf[i, 1] * h * rd0
                for jj in range(n):
                    s += Phi[i, jj] * x[jj]
                xl[i] = s
            if ns + 2 > su.shape[0]:  # room for the reversal this step may push
                su2 = np.zeros(2 * su.shape[0])
                sF2 = np.zeros(2 * su.shape[0])
                su2[: su.shape[0]] = su
                sF2[: su.shape[0]] = sF
                su = su2
                sF = sF2
            # predictor: r_nl extrapolated by the quadratic through (r_prev, r0, rd0)
            r1 = r0 + h * rd0 + (r0 - rp - h * rd0) if have_prev else r0 + h * rd0
            rd1 = rd0 + 2.0 * (r0 - rp - h * rd0) / h if have_prev else rd0
            z1 = 0.0
            v1 = 0.0
            for i in range(n):
                xp = xl[i] + Gf[i, 2] * r1 + Gf[i, 3] * h * rd1
                z1 += lz[i] * xp
                v1 += lv[i] * xp
            # evaluate the joint once, at the predicted motion, and commit its state
            Fj = 0.0
            Kd = 0.0
            Fiw = 0.0
            Kiw = 0.0
            zp = z1
            if jkind != 0:
                turn = False
                zt = 0.0
                if d != 0 and v1 * d < 0.0:
                    turn = True
                    zt = _hermite_tip(z0, v0, z1, v1, h, d)
                elif d != 0 and d * (z1 - z0) < 0.0:
                    turn = True
                    zt = z0
                if jkind == 1:
                    F, K, ns, d = advance(su, sF, ns, d, z1, zt, turn, KT, R, chi, phimax, Fs)
                    Fiw = F
                    Kiw = K
                else:
                    F = 0.0
                    K = 0.0
                    for i in range(sk.shape[0]):
                        xi = sx[i]
                        if turn:
                            xi = min(max(xi, zt - sphi[i]), zt + sphi[i])
                        if xi < z1 - sphi[i]:  # slipping: anchor dragged along
                            xi = z1 - sphi[i]
                        elif xi > z1 + sphi[i]:
                            xi = z1 + sphi[i]
                        else:  # stuck: contributes its stiffness to the tangent
                            K += sk[i]
                        sx[i] = xi
                        F += sk[i] * (z1 - xi)
                    if turn:
                        d = -d
                    elif d == 0 and z1 != 0.0:
                        d = 1 if z1 > 0.0 else -1
                Fj = F - KT * z1
                Kd = K - KT
            for sweep in range(2):
                r1 = Fj
                rd1 = Kd * v1
                cv = 0.0
                for e in range(n_el):
                    if codes[e] == 4:  # backbone share: -s (F_iwan - F_b), F_iwan moved along its tangent
                        fb, kb = _backbone(z1, KT, R, chi, phimax, Fs)
                        r1 -= coefs[e, 0] * (Fiw + Kiw * (z1 - zp) - fb)
                        rd1 -= coefs[e, 0] * (Kiw - kb) * v1
                        continue
                    fe, kz, ce = _element(codes[e], coefs[e, 0], coefs[e, 1], z1, v1)
                    r1 += fe
                    rd1 += kz * v1
                    cv += ce
                if cv != 0.0:  # a damper: its rate needs z'' at the step's end, from the total r_nl
                    ub = Wub[j, 0] * p0 + Wub[j, 1] * p1 + Wub[j, 2] * p2 + Wub[j, 3] * p3
                    zdd = bzu * ub + bzf * r1
                    for i in range(n):
                        zdd += az[i] * (xl[i] + Gf[i, 2] * r1 + Gf[i, 3] * h * rd1)
                    rd1 += cv * zdd
                if sweep == 1:
                    break
                # correct the state with the evaluated r_nl, then move the joint force to the
                # corrected displacement along its tangent (an O(h^4) shift: no second pow)
                z1 = 0.0
                v1 = 0.0
                for i in range(n):
                    x1[i] = xl[i] + Gf[i, 2] * r1 + Gf[i, 3] * h * rd1
                    z1 += lz[i] * x1[i]
                    v1 += lv[i] * x1[i]
                Fj += Kd * (z1 - zp)
            rp = r0
            have_prev = True
            for i in range(n):
                x[i] = x1[i]
            r0 = r1
            rd0 = rd1
            z0 = z1
            v0 = v1
        for o in range(n_y):
            s = dyu[o] * u[k + 1] + dyf[o] * r0
            for i in range(n):
                s += cy[o, i] * x[i]
            y_out[o, k + 1] = s
        z_out[k + 1] = z0
