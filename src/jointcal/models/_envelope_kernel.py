"""Numba kernel of the steady-state envelope model (private; see `jointcal.models.envelope`).

For every parameter set the first-harmonic balance of the joint DOF reduces to one
scalar fixed point in s = log q (q the joint's relative amplitude, in):

    r(s) = s + log|K_z(q, omega) - mu(omega)| - log|B(omega)| = 0,

with K_z the joint DOF's complex dynamic stiffness at amplitude q (linear spring,
dashpot, Iwan describing function, the element table's describing functions) and mu, B the
effective inertia and effective base load of the structure around it (a rigid base:
mu = m omega^2, B = m A; a flexible fixture: see `envelope._structure_terms`). Stable
branches have dr/ds > 0. The kernel marches over the frequencies in sweep order and
continues the branch of the previous frequency by a bracketed Newton iteration; when
the branch ends at a fold the iteration lands on the other branch, which is flagged.

The same K_z carries the sweep's transient (`jointcal.models.swept`): `stiffness_slopes`
gives its derivatives at a solution, `slow_flow` integrates the averaged (slow-flow)
equation of the joint DOF in a frame rotating with the drive.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__: list[str] = []

PI = np.pi


@njit(cache=True, inline="always")
def _jenkins(s):
    """In-phase first-harmonic stiffness g(s) of a unit Jenkins element (s = phi/q)."""
    if s >= 1.0:
        return 1.0
    if s <= 0.0:
        return 0.0
    th = np.arccos(1.0 - 2.0 * s)
    return (th - 0.5 * np.sin(2.0 * th)) / PI


@njit(cache=True, nogil=True)
def _J(chi, smax, nodes, weights):
    """J = int_0^smax (1 - g(s)) s^chi ds (as `amplitude._J`: split at s = 1/2)."""
    a = chi + 1.0
    t_a = min(smax, 0.5) ** a
    low = 0.0
    for i in range(nodes.shape[0]):
        s = (t_a * nodes[i]) ** (1.0 / a)
        low += weights[i] * (1.0 - _jenkins(s))
    low *= t_a / a
    high = 0.0
    if smax > 0.5:
        th0 = 0.5 * PI
        th1 = np.arccos(1.0 - 2.0 * smax)
        for i in range(nodes.shape[0]):
            th = th0 + (th1 - th0) * nodes[i]
            sb = 0.5 * (1.0 - np.cos(th))
            omg = 1.0 - (th - 0.5 * np.sin(2.0 * th)) / PI
            high += weights[i] * omg * sb**chi * 0.5 * np.sin(th)
        high *= th1 - th0
    return low + high


@njit(cache=True, inline="always")
def _cubic(q, a, re, dre):
    """Cubic spring a z^3: 3/4 a q^2 in phase (added to re, and its q-slope to dre)."""
    return re + 0.75 * a * q * q, dre + 2.0 * (0.75 * a * q * q)


@njit(cache=True, inline="always")
def _quadratic_damper(q, w, a, im, dim, C, C1):
    """Quadratic damper a z'|z'|: omega c_eq with c_eq = 8 a omega q / (3 pi); C, C1 its omega-slopes."""
    t = 8.0 * a * w * w * q / (3.0 * PI)
    return im + t, dim + t, C + 16.0 * a * w * q / (3.0 * PI), C1 + 16.0 * a * q / (3.0 * PI)


@njit(cache=True, nogil=True)
def _backbone_first_harmonic(q, KT, R, chi, phimax, nodes, weights):
    """First-harmonic stiffness k_b (lbf/in) of the Iwan joint's virgin backbone F_b taken as an elastic
    spring, at amplitude q (in), and its slope dk_b / dlog q.

    k_b = (4 / (pi q)) I, I = int_0^{pi/2} F_b(q cos t) cos t dt with F_b = KT z - R' z^n (n = chi + 2,
    R' = R / ((chi + 1)(chi + 2))) below phi_max and Fs beyond (`iwan.backbone`). With t_c = arccos(phi_max / q)
    (0 in microslip), I = Fs sin t_c + KT q (pi/4 - t_c/2 - sin(2 t_c)/4) - R' q^n M, M = int_{t_c}^{pi/2}
    cos^{n+1} t dt: in microslip Wallis' integral sqrt(pi)/2 Gamma((n + 2)/2) / Gamma((n + 3)/2), in macroslip
    Gauss-Legendre on the nodes. F_b is continuous at t_c, so the t_c-terms of dI/dq
    cancel: dI/dq = KT (pi/4 - t_c/2 - sin(2 t_c)/4) - n R' q^{n-1} M, and dk_b/dlog q = (4/pi)(dI/dq - I/q).
    """
    n = chi + 2.0
    Rp = R / ((chi + 1.0) * (chi + 2.0))
    if q <= phimax:  # microslip: Wallis' integral
        tc = 0.0
        M = 0.5 * np.sqrt(PI) * np.exp(math.lgamma(0.5 * (n + 2.0)) - math.lgamma(0.5 * (n + 3.0)))
    else:
        tc = np.arccos(phimax / q)
        M = 0.0
        for i in range(nodes.shape[0]):
            t = tc + (0.5 * PI - tc) * nodes[i]
            M += weights[i] * np.cos(t) ** (n + 1.0)
        M *= 0.5 * PI - tc
    lin = 0.25 * PI - 0.5 * tc - 0.25 * np.sin(2.0 * tc)
    Fs = KT * phimax - Rp * phimax**n  # the backbone at phi_max
    I = Fs * np.sin(tc) + KT * q * lin - Rp * q**n * M
    dI = KT * lin - n * Rp * q ** (n - 1.0) * M
    return 4.0 * I / (PI * q), 4.0 * (dI - I / q) / PI


@njit(cache=True, inline="always")
def _stiffness(q, s, w, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights):
    """Complex dynamic stiffness of the joint DOF at amplitude q (in) and omega w (rad/s).

    Returns (Re, Im, dRe/ds, dIm/ds, C, C1) with s = log q (passed too: q^e = exp(e s)), C = dIm/domega at
    fixed q (lbf s/in), C1 = dC/domega. kp: linear springs in parallel (k); c: dashpot; Iwan (KT, R, chi,
    phimax, S; J1 = J(chi, 1)); codes (n_e,), coefs (n_e, 2): the element table (`models.elements`).
    """
    re, im, dre, dim = 0.0, 0.0, 0.0, 0.0  # the Iwan joint's own part first (a backbone share scales it)
    if KT > 0.0:
        e = chi + 1.0
        if q <= phimax:
            p = R * np.exp(e * s)
            re += KT - p * J1  # in-phase stiffness of the power-law sliders
            dre -= e * p * J1
            Dq = 4.0 * p / (PI * (chi + 2.0) * (chi + 3.0))  # D(q)/(pi q^2), D = 4 R q^(chi+3)/((chi+2)(chi+3))
            im += Dq
            dim += e * Dq
        else:  # macroslip (eqs. 3.3-3.7 with the delta S at phi_max): exact derivatives in q
            sm = phimax / q
            qe = R * np.exp(e * s)
            J = _J(chi, sm, nodes, weights)
            g = _jenkins(sm)
            re += KT - qe * J - S * (1.0 - g)
            dJ = (1.0 - g) * sm**chi  # dJ/dsmax: the integrand at the upper limit
            th = np.arccos(1.0 - 2.0 * sm)
            dg = 4.0 * np.sin(th) / PI  # dg/ds
            # q d/dq: smax = phimax/q moves as -smax
            dre -= e * qe * J - qe * dJ * sm + S * dg * sm
            u = phimax
            D = 4.0 * R * (q * u ** (chi + 2.0) / (chi + 2.0) - u ** (chi + 3.0) / (chi + 3.0))
            D += 4.0 * S * phimax * (q - phimax)
            dD = 4.0 * R * u ** (chi + 2.0) / (chi + 2.0) + 4.0 * S * phimax  # dD/dq
            im += D / (PI * q * q)
            dim += (q * dD - 2.0 * D) / (PI * q * q)
    for i in range(codes.shape[0]):  # a backbone share: (1 - s) of the Iwan joint + s of its elastic backbone
        if codes[i] == 4 and KT > 0.0:
            kb, dkb = _backbone_first_harmonic(q, KT, R, chi, phimax, nodes, weights)
            sh = coefs[i, 0]
            re, im, dre, dim = (1.0 - sh) * re + sh * kb, (1.0 - sh) * im, (1.0 - sh) * dre + sh * dkb, (1.0 - sh) * dim
    re += kp
    im += w * c
    C, C1 = c, 0.0  # dIm/domega at fixed q, and its own omega-slope
    for i in range(codes.shape[0]):  # the element table: one inline function per kind
        if codes[i] == 1:  # cubic spring
            re, dre = _cubic(q, coefs[i, 0], re, dre)
        elif codes[i] == 3:  # quadratic damper
            im, dim, C, C1 = _quadratic_damper(q, w, coefs[i, 0], im, dim, C, C1)
    return re, im, dre, dim, C, C1


@njit(cache=True, inline="always")
def _residual(s, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights):
    """r(s) and dr/ds of the amplitude fixed point."""
    q = np.exp(s)
    re, im, dre, dim, _, _ = _stiffness(q, s, w, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights)
    x = re - mu_re
    y = im - mu_im
    m2 = x * x + y * y
    r = s + 0.5 * np.log(m2) - logB
    dr = 1.0 + (x * dre + y * dim) / m2
    return r, dr, re, im


@njit(cache=True, nogil=True)
def _root(s0, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights, tol):
    """A stable root of r near s0 (bracketed Newton), and whether the walk left a vanished branch.

    From s0 the search walks towards the sign change that r(s0) points to (down if
    r > 0, up if r < 0, as dr/ds > 0 on stable branches); a local extremum of r met on
    the way means the branch of s0 has ended at a fold (a jump).
    """
    r0, d0, re, im = _residual(s0, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights)
    if abs(r0) < tol:
        return s0, False, re, im
    direction = -1.0 if r0 > 0.0 else 1.0
    # Newton guess (if it points the right way) sets the first step
    step = 0.02
    if d0 > 0.0:
        step = min(max(abs(r0 / d0), 1e-6), 0.25)
    a, ra, da, rea, ima = s0, r0, d0, re, im  # each end keeps its residual, slope and K_z: none is evaluated twice
    rprev = r0
    jumped = False
    b, rb, db, reb, imb = a, ra, da, rea, ima
    for _ in range(200):
        b = a + direction * step
        rb, db, reb, imb = _residual(b, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes,
                                     weights)
        if abs(rb) < tol and not jumped:  # the Newton step from a continued guess has converged
            return b, False, reb, imb
        if rb * ra <= 0.0:
            break
        if abs(rb) > abs(rprev):  # moving away from zero: r turned at an extremum, the branch is gone
            jumped = True
        rprev = rb
        a, ra, da, rea, ima = b, rb, db, reb, imb
        step = min(step * 1.6, 0.5)
    # bracket [a, b] (unordered): safeguarded Newton from the end nearer the root
    lo, hi = (a, b) if a < b else (b, a)
    rlo = ra if a < b else rb
    if abs(rb) < abs(ra):
        s, r, dr, re, im = b, rb, db, reb, imb
    else:
        s, r, dr, re, im = a, ra, da, rea, ima
    for it in range(100):
        if it > 0:
            r, dr, re, im = _residual(s, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes,
                                      weights)
        if abs(r) < tol:
            return s, jumped, re, im
        if (r < 0.0) == (rlo < 0.0):
            lo = s
            rlo = r
        else:
            hi = s
        sn = s - r / dr if dr != 0.0 else 0.5 * (lo + hi)
        if not (lo < sn < hi):
            sn = 0.5 * (lo + hi)
        if hi - lo < tol:
            break
        s = sn
    r, dr, re, im = _residual(s, w, mu_re, mu_im, logB, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights)
    return s, jumped, re, im


def _solve(w, mu_re, mu_im, logB, s_start, order, bounds, kp, c, KT, R, chi, phimax, S, J1, codes, coefs,
           nodes, weights, tol, s_out, jump_out, kre_out, kim_out):
    """Amplitudes s = log q (P, N) by continuation along each segment's `order` for every parameter set.

    w (N,) rad/s; mu_re, mu_im, logB (P, N); segment g is continued along order[bounds[g]:bounds[g + 1]]
    (indices into the N frequencies: several runs laid end to end, each continued on its own, as a run alone
    would be) from s_start[g] (P,), a guess for its first frequency (below every branch for an up sweep's low
    end, see `envelope`); parameter arrays (P,). Writes s_out, jump_out and the joint DOF's dynamic stiffness
    at the solution (kre_out + i kim_out, lbf/in), all (P, N).
    """
    P = mu_re.shape[0]
    for p in prange(P):  # a plain range unless compiled parallel
        for g in range(bounds.shape[0] - 1):
            first = bounds[g]
            s = s_start[g, p]
            s_prev = s
            for jj in range(bounds[g + 1] - first):
                n = order[first + jj]
                guess = s
                if jj >= 2:  # continue the branch by linear extrapolation in frequency
                    n1 = order[first + jj - 1]
                    n2 = order[first + jj - 2]
                    if w[n1] != w[n2]:  # at most a factor e: frames close in frequency must not throw it far
                        guess = s + max(-1.0, min(1.0, (s - s_prev) * (w[n] - w[n1]) / (w[n1] - w[n2])))
                s_prev = s
                s, jumped, re, im = _root(guess, w[n], mu_re[p, n], mu_im[p, n], logB[p, n], kp[p], c[p], KT[p],
                                          R[p], chi[p], phimax[p], S[p], J1[p], codes, coefs[p], nodes, weights, tol)
                s_out[p, n] = s
                jump_out[p, n] = jumped and jj > 0
                kre_out[p, n] = re
                kim_out[p, n] = im


solve = njit(cache=True, nogil=True)(_solve)
solve_parallel = njit(cache=True, parallel=True)(_solve)  # the same kernel with the sets spread over threads


@njit(cache=True, nogil=True)
def rigid_output(kre, kim, mu, mA, w, A, gain, tau, Z_out, T_out):
    """Rigid base, in one pass: Z = -m A / (K_z - m omega^2), T = gain (1 - omega^2 Z / A) e^{-i omega tau}."""
    P, N = kre.shape
    for p in range(P):
        for n in range(N):
            z = -mA[p, n] / complex(kre[p, n] - mu[p, n], kim[p, n])
            Z_out[p, n] = z
            t = gain[p] * (1.0 - w[n] * w[n] * z / A[n])
            if tau[p] != 0.0:
                t *= np.exp(complex(0.0, -w[n] * tau[p]))
            T_out[p, n] = t


@njit(cache=True, nogil=True)
def stiffness_slopes(q, w, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights, out):
    """K_z and its slopes at amplitudes q (P, N), omega w (N,); parameter arrays (P,), coefs (P, n_e, 2).

    Writes out (6, P, N): Re K_z, Im K_z, dRe/dlog q, dIm/dlog q (lbf/in), C = dIm/domega at fixed q
    (lbf s/in: the dashpot c and the quadratic damper's 16 a omega q / (3 pi)) and dC/domega.
    """
    P, N = q.shape
    for p in range(P):
        for n in range(N):
            qq = max(q[p, n], 1e-300)
            re, im, dre, dim, C, C1 = _stiffness(qq, np.log(qq), w[n], kp[p], c[p], KT[p], R[p], chi[p], phimax[p],
                                                 S[p], J1[p], codes, coefs[p], nodes, weights)
            out[0, p, n] = re
            out[1, p, n] = im
            out[2, p, n] = dre
            out[3, p, n] = dim
            out[4, p, n] = C
            out[5, p, n] = C1


@njit(cache=True, inline="always")
def _flow(z, w, al, p0, g0, m1, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights):
    """Z' of the slow flow (m1 + C) Z' = g0 - (K_z(|Z|, w) + p0 + alpha C' / 2) Z, and the joint force.

    C = dIm K_z / domega (dashpot, dampers) turns the envelope's rate into force,
    C' = dC/domega its sweep term; the joint force is (K_z + alpha C' / 2) Z + C Z'.
    """
    q = max(abs(z), 1e-300)
    re, im, dre, dim, C, C1 = _stiffness(q, np.log(q), w, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes,
                                         weights)
    kz = complex(re, im) + 0.5 * al * C1
    zdot = (g0 - (kz + p0) * z) / (m1 + C)
    return zdot, kz * z + C * zdot


@njit(cache=True, nogil=True)
def slow_flow(z0, h, w, al, p0, g0, m1, kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes, weights, force_out):
    """RK4 of the slow flow (`_flow`) from Z(0) = z0 for one parameter set.

    Nodes t_j = j h, j = 0 .. n-1; omega w, alpha al and the coefficients p0, g0, m1 are given
    at half steps, shape (2n - 1,) (index 2j at node j). Writes the joint force at the nodes
    into force_out (n,).
    """
    n = force_out.shape[0]
    z = z0
    for j in range(n):
        i = 2 * j
        k1, force = _flow(z, w[i], al[i], p0[i], g0[i], m1[i], kp, c, KT, R, chi, phimax, S, J1, codes, coefs, nodes,
                          weights)
        force_out[j] = force
        if j == n - 1:
            break
        k2, _ = _flow(z + 0.5 * h * k1, w[i + 1], al[i + 1], p0[i + 1], g0[i + 1], m1[i + 1], kp, c, KT, R, chi,
                      phimax, S, J1, codes, coefs, nodes, weights)
        k3s, _ = _flow(z + 0.5 * h * k2, w[i + 1], al[i + 1], p0[i + 1], g0[i + 1], m1[i + 1], kp, c, KT, R, chi,
                       phimax, S, J1, codes, coefs, nodes, weights)
        k4, _ = _flow(z + h * k3s, w[i + 2], al[i + 2], p0[i + 2], g0[i + 2], m1[i + 2], kp, c, KT, R, chi,
                      phimax, S, J1, codes, coefs, nodes, weights)
        z = z + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3s + k4)
