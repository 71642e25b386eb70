"""Resonance and damping of a swept run from its whole transient, at the amplitude it reached.

A lab's FRF (`jointcal.frf`) assumes each line is a steady state. A chirp faster than a
lightly damped nonlinear mode can follow breaks that: the amplitude never builds, the
response rings on after the drive has moved away, and a softening joint's peak is read
at amplitudes it never had. Here the run is instead fitted, sample by sample, with one
mode whose natural frequency and damping depend on its amplitude, driven by the
measured reference:

    x_a'' + (1 - phi) D(q) x_a' + (Omega(q)^2 + i phi D(q) Omega(q)) x_a = A(w) r_a(t),    q = |x_a|,

with x_a, r_a the analytic signals of the displacement and the reference, D = 2 zeta
Omega shared between a viscous part and a hysteretic part phi (a joint's friction: its
loss per cycle does not grow with frequency; phi matters where the data lie off Omega,
e.g. a force-driven rig's response peaks at the shaker-loaded resonance), and A(w) the
modal constant at the drive frequency w: 1/m for a force at the driving point (real, no
slope), complex and linear in w for an amplifier voltage, A = A_0 + A_1 (w / W_0 - 1)
(the shaker's electrical phase and the residual modes).

Written in a frame rotating at the fixed frequency W_0 (the start value), x_a = Z e^{i W_0 t},
r_a = R e^{i W_0 t}, this is exactly

    Z'' + (2 i W_0 + c) Z' + (Omega^2 - W_0^2 + i (c W_0 + phi D Omega)) Z = A_0 R - i A_1 R' / W_0,   c = (1 - phi) D,

(w r_a becomes W_0 R - i R' in the frame, so the slope needs no estimate of the drive
frequency). Z and R are the measured signals demodulated at W_0 and low-passed at
`cutoff` W_0: the mode's resonant passage, its forced response within that band and its
free ring-down after the drive has left (or stopped) all stay in the band, while the
drive far from the mode (a chirp from almost 0 Hz), other modes and harmonics are
filtered out of the data and the model alike. A fixed frame makes the low-pass the same
for the ring-down and the forced response: a frame that follows the drive would filter
the ring-down out of the data once the drive has moved on, but not out of the model.
The equation is integrated by RK4 at a few steps per cycle (the negative-frequency root
-(Omega + W_0) bounds the step), and its acceleration Z'' + 2 i W_0 Z' - W_0^2 Z is compared
with the measured one, sample by sample, over the passage through resonance and the
ring-down (`window`). For a linear mode this is the exact response at any sweep rate; for
an amplitude-dependent one it is the first-harmonic (averaged) response, the same
approximation as the harmonic-balance truth.

ln Omega^2(q) and ln D(q) are a cubic and a quadratic in L = ln(q / q_ref) around the
largest amplitude the run reached, q_ref (a power law, as a joint's microslip softening and
loss, eq. 3.5, has in its first term, is a straight line in L; D stays positive), held
constant outside the amplitudes the fitted window holds. The frequency's curvature (the
Table 3.2 joint's softening steepens toward macroslip) is kept only where the Bayesian
information criterion of the misfit asks for it (a curvature fitted to noise bends the
backbone's ends: +0.14% at q_in on a jointed beam at eta 500); the damping's carries a
ridge (`curv`). The fit
(`scipy.optimize.least_squares`: the modal constant, the shape coefficients, Omega and D at
q_ref, phi in [0, 1], and residual terms (B_0 + B_1 (w / W_0 - 1) + B_2 (w / W_0 - 1)^2) r_a for
the other modes' mass or stiffness lines)
returns Omega and zeta = D / (2 Omega) at the largest amplitude the fitted response
reached, `q_in`: the equivalent-linear resonance and damping at the amplitude the
structure reached, and the backbone below it.

Bad samples (NaN or inf) in either channel are left out: the response's frames within a
filter length of them leave the misfit, and the drive's demodulated envelope is bridged
across them as the swept sine it is (a quadratic phase and a log-linear magnitude fitted on
both sides).
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray
from scipy import signal
from scipy.optimize import least_squares

from .units import G

__all__ = ["SweepFit", "baseband", "fit_swept_mode"]


@dataclass(frozen=True)
class SweepFit:
    """A swept run's amplitude-dependent single-mode fit.

    f_hz, zeta : natural frequency Omega / 2 pi (Hz) and damping ratio at q_in.
    q_in : the largest displacement amplitude the fitted response reached (in): the
        amplitude f_hz and zeta belong to.
    q_low_in : the smallest amplitude the fitted window holds (in); the backbone
        (`backbone`) is fitted over [q_low_in, q_in].
    residual : relative RMS misfit of the response's acceleration envelope over the window.
    coef : (Omega_ref^2 (rad^2/s^2), D_ref (1/s), a1, a2, b1, b2, phi, q_ref (in), L_lo, L_hi, a3):
        Omega^2 = Omega_ref^2 exp(a1 L + a2 L^2 + a3 L^3), D = 2 zeta Omega = D_ref exp(b1 L + b2 L^2),
        L = ln(q / q_ref) held within [L_lo, L_hi]; phi the hysteretic share of D (0 viscous,
        1 hysteretic).
    modal_constant : complex A_0 at W_0 ((in/s^2) per reference unit: 1/m in 1/(lbf s^2/in)
        for a force at the driving point).
    modal_slope : complex A_1 (same unit): A(w) = A_0 + A_1 (w / W_0 - 1).
    w0 : the frame's frequency W_0, rad/s.
    fraction_bad : share of the fitted window left out for bad samples.
    """

    f_hz: float
    zeta: float
    q_in: float
    q_low_in: float
    residual: float
    coef: tuple
    modal_constant: complex = complex("nan")
    modal_slope: complex = 0j
    w0: float = float("nan")
    fraction_bad: float = 0.0

    def backbone(self, q: NDArray) -> tuple[NDArray, NDArray]:
        """Natural frequency (Hz) and damping ratio at amplitudes q (in) (fitted over [q_low_in, q_in])."""
        w2r, dr, a1, a2, b1, b2, _, qr, l_lo, l_hi, a3 = self.coef
        L = np.clip(np.log(np.asarray(q, float) / qr), l_lo, l_hi)
        om = np.sqrt(w2r * np.exp(a1 * L + a2 * L**2 + a3 * L**3))
        return om / (2 * np.pi), dr * np.exp(b1 * L + b2 * L**2) / (2 * om)  # at w = Omega


@numba.njit(cache=True)
def _rhs(z, y, r, rd, w0, p, q_ref, l_lo, l_hi):
    L = np.log(max(abs(z), 1e-300) / q_ref)
    L = min(max(L, l_lo), l_hi)
    w2 = p[0] * np.exp(p[2] * L + p[3] * L * L + p[11] * L * L * L)
    d = p[1] * np.exp(p[4] * L + p[5] * L * L)  # 2 zeta Omega at q
    c = (1.0 - p[8]) * d  # the viscous share; the hysteretic share p[8] d Omega does not scale with w
    force = (p[6] + 1j * p[7]) * r - 1j * (p[9] + 1j * p[10]) * rd / w0  # A(w) r_a in the frame
    return force - (2j * w0 + c) * y - (w2 - w0 * w0 + 1j * (c * w0 + p[8] * d * np.sqrt(w2))) * z


@numba.njit(cache=True)
def _rotating_mode(r, rd, rm, rdm, w0, h, p, q_ref, l_lo, l_hi, z0, y0):
    """RK4 of the mode in the frame rotating at w0 from (Z, Z') = (z0, y0).

    r, rd: the drive's envelope and its rate at the steps; rm, rdm: at the midpoints.

    Returns Z (in) and its acceleration envelope Z'' + 2 i w0 Z' - w0^2 Z (in/s^2).
    """
    n = r.size
    Z = np.empty(n, np.complex128)
    acc = np.empty(n, np.complex128)
    z, y = z0, y0
    for k in range(n):
        a1 = _rhs(z, y, r[k], rd[k], w0, p, q_ref, l_lo, l_hi)
        Z[k] = z
        acc[k] = a1 + 2j * w0 * y - w0 * w0 * z
        if k == n - 1:
            break
        a2 = _rhs(z + 0.5 * h * y, y + 0.5 * h * a1, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi)
        a3 = _rhs(z + 0.5 * h * (y + 0.5 * h * a1), y + 0.5 * h * a2, rm[k], rdm[k], w0, p, q_ref, l_lo, l_hi)
        a4 = _rhs(z + h * (y + 0.5 * h * a2), y + h * a3, r[k + 1], rd[k + 1], w0, p, q_ref, l_lo, l_hi)
        z = z + h * y + h * h / 6.0 * (a1 + a2 + a3)
        y = y + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return Z, acc


def baseband(x: NDArray, fs: float, w0: float, cutoff_hz: float) -> NDArray:
    """Complex envelope of x in a frame rotating at w0 (rad/s): low-pass of 2 x e^{-i w0 t}.

    Zero-phase 4th-order Butterworth at cutoff_hz (flat to 1e-4 below half the cutoff); the
    negative-frequency image at -(w + w0) lies beyond it. A local operation (no Hilbert
    transform), so a bad sample spoils only a filter length around it.
    """
    t = np.arange(x.size) / fs
    y = 2.0 * x * np.exp(-1j * w0 * t)
    sos = signal.butter(4, min(cutoff_hz, 0.45 * fs), fs=fs, output="sos")
    return signal.sosfiltfilt(sos, y.real) + 1j * signal.sosfiltfilt(sos, y.imag)


def _dilate(bad: NDArray[np.bool_], n: int) -> NDArray[np.bool_]:
    """bad widened by n samples on each side."""
    if n <= 0 or not bad.any():
        return bad
    return np.convolve(bad.astype(float), np.ones(2 * n + 1), mode="same") > 0.5


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """[start, stop) of each run of True in mask."""
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _bridge(x: NDArray, bad: NDArray[np.bool_]) -> NDArray:
    """A swept drive's complex envelope across its bad stretches: a chirp in the frame.

    On the good samples beside each bad stretch (as many as it is long, on each side) the phase
    is fitted by a quadratic in time (a linear sweep's phase, unwrapped across the stretch by the
    whole number of turns its two sides' slopes predict) and the log-magnitude by a line; the
    stretch takes their values. A stretch with one good side keeps that side's extrapolation.
    """
    if not bad.any():
        return x
    if (~bad).sum() < 8:
        raise ValueError("the drive channel has too few good samples near the mode.")
    out = x.copy()
    idx = np.arange(x.size)
    for a, b in _runs(bad):
        n = max(b - a, 8)
        sides = [s for s in (idx[max(0, a - n):a], idx[b:b + n]) if s.size >= 4 and np.all(~bad[s])]
        sides = [s[np.abs(x[s]) > 0] for s in sides]
        sides = [s for s in sides if s.size >= 4]
        if not sides:
            raise ValueError("a bad stretch of the drive has no good samples beside it to bridge it from.")
        t0 = 0.5 * (a + b)
        phases = [np.unwrap(np.angle(x[s])) for s in sides]
        if len(sides) == 2:  # the right side's turns counted from the left side's extrapolation
            cl = np.polyfit(sides[0] - t0, phases[0], min(2, sides[0].size - 2))
            guess = np.polyval(cl, sides[1][0] - t0)
            phases[1] += 2 * np.pi * np.round((guess - phases[1][0]) / (2 * np.pi))
        t = np.concatenate(sides) - t0
        deg = 2 if t.size >= 8 else 1
        ph = np.polyfit(t, np.concatenate(phases), deg)
        lm = np.polyfit(t, np.log(np.abs(x[np.concatenate(sides)])), 1)
        tt = idx[a:b] - t0
        out[a:b] = np.exp(np.polyval(lm, tt) + 1j * np.polyval(ph, tt))
    return out


def _window(mag: NDArray, ok: NDArray[np.bool_], frac: float, quiet: float,
            max_lead: int = 20000) -> tuple[int, int, int]:
    """The fitted segment [i0, i1]: the contiguous run around the peak where mag > frac peak (bad
    samples bridged); and where the integration starts: at rest at the record's start (0) when at
    most max_lead steps lie before the segment (a fast chirp), else at the last sample before it
    under quiet x peak (a slow sweep: from the quasi-static forced state there; 0 if there is none)."""
    m = np.where(ok, mag, 0.0)
    ip = int(np.argmax(m))
    above = np.where(ok, mag > frac * m[ip], True)  # a bad stretch does not cut the segment
    i0 = ip
    while i0 > 0 and above[i0 - 1]:
        i0 -= 1
    i1 = ip
    while i1 < mag.size - 1 and above[i1 + 1]:
        i1 += 1
    if i0 <= max_lead:
        return 0, i0, i1
    low = np.flatnonzero(ok[:i0] & (mag[:i0] < quiet * m[ip]))
    return (int(low[-1]) if low.size else 0), i0, i1


def fit_swept_mode(ref: NDArray, resp_g: NDArray, fs: float, f0: float, zeta0: float, *,
                   modal_phase: float | None = None, window: float = 0.15, cutoff: float = 0.45,
                   steps_per_cycle: float = 6.0, quiet: float = 0.02, ridge: float = 0.01,
                   curv: float = 0.3, residual_ridge: float = 0.3,
                   frequency_curvature: str = "bic", earn: float = 1.5) -> SweepFit:
    """Fit one amplitude-dependent mode to a swept run (see the module docstring).

    Parameters
    ----------
    ref : ndarray, shape (n,)
        Reference channel (force, lbf; amplifier voltage, V; any unit: A absorbs it); NaN or
        inf samples are bridged.
    resp_g : ndarray, shape (n,)
        Response acceleration at the driving point (or any point of a single mode), g; NaN
        or inf samples are left out of the misfit.
    fs : float
        Sample rate, Hz.
    f0, zeta0 : float
        Start values: the resonance (Hz) and damping ratio (e.g. from the FRF read-out). f0
        is also the frame's frequency W_0 / 2 pi.
    modal_phase : float, optional
        The modal constant's phase where physics fixes it (rad): 0 for a force on the
        structure (A = 1/m, no frequency dependence). None (an amplifier voltage): A complex
        and sloped in w.
    window : float
        Samples of the contiguous stretch around the response's peak whose envelope
        exceeds this fraction of the peak are fitted (the passage through resonance and
        the ring-down).
    cutoff : float
        Low-pass of the demodulated signals, as a fraction of f0: other modes must lie
        further than this from f0 (0.45: beyond 0.55 f0 and 1.45 f0; a mode within is
        not separated from this one).
    steps_per_cycle : float
        RK4 steps per period at f0, about (the rotating frame's fast root -(Omega + W_0)
        bounds it: 6 keeps |lambda| h near 2.1, under RK4's 2.8).
    quiet : float
        The integration starts at the last sample before the window where the envelope is
        under this fraction of its peak, from the forced state there.
    ridge : float
        Weight of a ridge penalty on the nuisance terms (the modal constant's slope over its
        value, the residual terms over the peak): a value of 1 costs as much as a relative
        misfit of `ridge` on every sample.
    frequency_curvature : {'bic', 'always', 'never'}
        Whether ln Omega^2 takes its quadratic and cubic terms in L: where the Bayesian information
        criterion of the misfit asks for them (default), always or never.
    earn : float
        The residual terms are kept only where they pass the Bayesian information criterion and cut
        the misfit's sum of squares by this factor.
    residual_ridge : float
        The residual terms' share of that penalty (0.3: other modes' lines must be free enough to
        follow a second mode's stiffness line over the band, whose curvature biased the resonance
        by +0.05-0.1% on a jointed beam at eta 500 with only the constant and slope terms).
    curv : float
        The same penalty, times curv, on the curvature of ln D in L over the window
        (b2 L_lo^2): the damping is a power law in q unless the data ask for more (measured
        on a jointed beam at eta 500 with 2% noise: the damping at the window's ends off by
        5-11% without it, within 2% with 0.3). The frequency's curvature, which the phase
        pins, is free.

    Returns
    -------
    SweepFit

    Raises
    ------
    ValueError
        When the record holds no drive or no response, or too few good samples.
    """
    r = np.asarray(ref, float)
    a = np.asarray(resp_g, float) * G
    bad_r, bad_a = ~np.isfinite(r), ~np.isfinite(a)
    if bad_r.mean() > 0.5 or bad_a.mean() > 0.5:
        raise ValueError("more than half of the record's samples are NaN or inf.")
    r = np.where(bad_r, 0.0, r - np.median(r[~bad_r]))
    a = np.where(bad_a, 0.0, a - np.median(a[~bad_a]))
    if not (np.ptp(r) > 0 and np.ptp(a) > 0 and f0 > 0 and zeta0 > 0):
        raise ValueError("the swept-mode fit needs a drive, a response and start values f0 > 0, zeta0 > 0.")
    W0 = 2 * np.pi * f0
    fc = cutoff * f0
    margin = int(np.ceil(3.0 / fc * fs))  # a filter length: the bad samples' reach after the low-pass
    # the record starts at the start of the sweep, from rest: zeros before it keep the zero-phase
    # filter's start consistent between the drive and the response (and the model starts at rest there)
    pad = np.zeros(margin)
    r, a = np.concatenate([pad, r]), np.concatenate([pad, a])
    bad_r, bad_a = np.concatenate([pad.astype(bool), bad_r]), np.concatenate([pad.astype(bool), bad_a])
    R, Acc = baseband(r, fs, W0, fc), baseband(a, fs, W0, fc)
    bad_R, bad_A = _dilate(bad_r, margin), _dilate(bad_a, margin)
    up = int(np.ceil(2 * steps_per_cycle * f0 / fs))  # a record sampled under 2 x 6 per cycle: the
    if up > 1:                                       # envelopes (band-limited below cutoff f0) upsampled
        R, Acc = (signal.resample_poly(x.real, up, 1) + 1j * signal.resample_poly(x.imag, up, 1) for x in (R, Acc))
        bad_R, bad_A = np.repeat(bad_R, up), np.repeat(bad_A, up)
    fs_b = fs * up
    half = max(1, int(round(fs_b / (2 * steps_per_cycle * f0))))  # samples per RK4 half step
    h = 2 * half / fs_b
    Rh = R[::half]  # the drive at every half step: RK4's midpoints see it exactly, not interpolated
    Rh = _bridge(Rh, bad_R[::half])
    Rdh = np.gradient(Rh, h / 2)
    Rddh = np.gradient(Rdh, h / 2)
    R, Rd, Rdd = Rh[::2], Rdh[::2], Rddh[::2]
    Rm, Rdm = Rh[1::2], Rdh[1::2]
    Acc, bad_A = Acc[::2 * half][:R.size], bad_A[::2 * half][:R.size]
    mag = np.abs(Acc)
    ok = ~bad_A
    i_start, i0, i1 = _window(mag, ok, window, quiet)
    R, Rd, Rdd, Acc, ok, mag = (x[i_start:i1 + 1] for x in (R, Rd, Rdd, Acc, ok, mag))
    Rm, Rdm = Rm[i_start:i1], Rdm[i_start:i1]
    win = ok & (np.arange(mag.size) >= i0 - i_start)
    # the misfit on every third step (2 samples per cycle at f0): the envelopes are band-limited below
    # cutoff f0, so this loses nothing and cuts the least-squares algebra threefold
    sel = win & (np.arange(mag.size) % max(1, int(steps_per_cycle // 2)) == 0)
    if sel.sum() < 16:
        raise ValueError("the response's passage through the mode holds too few good samples to fit.")
    # the forced state at the start: displacement -Acc / w^2 at the local frequency w = W0 + arg rate
    if i_start > 0 and ok[0]:
        w_loc = W0 + float(np.angle(Acc[1] / Acc[0])) / h if abs(Acc[0]) > 0 else W0
        w_loc = min(max(w_loc, 0.3 * W0), 3.0 * W0)
        z_start = complex(-Acc[0] / w_loc**2)
        y_start = complex(1j * (w_loc - W0) * z_start)
    else:
        z_start = y_start = 0j
    peak = float(mag[sel].max())
    ip = int(np.flatnonzero(sel)[np.argmax(mag[sel])])
    q_ref = peak / W0**2
    l_lo, l_hi = float(np.log(0.5 * window)), float(np.log(1.5))
    r_abs = float(np.abs(R[sel]).max())
    if not r_abs > 0:
        raise ValueError("the drive channel holds no signal near the mode.")
    a_abs = 2 * zeta0 * peak / r_abs  # |A| of a steady resonance: |Acc| = |A| |R| / (2 zeta)
    b_abs = peak / r_abs

    fixed = modal_phase is not None  # a force at the driving point: A = |A| e^{i phase}, no slope; real residuals
    rot = np.exp(1j * modal_phase) if fixed else 1.0
    free_all = np.array([0, 1, 2, 3, 4, 5, 6, 8, 11, 13, 15, 16] if fixed else list(range(18)))
    free = free_all[~np.isin(free_all, (3, 15))]  # ln Omega^2 linear in L first; its curvature if the data ask

    def params(pf):
        p = np.zeros(18)
        p[free] = pf
        a = p[6] * rot if fixed else p[6] + 1j * p[7]
        mode = np.array([W0**2 * np.exp(2 * p[0]), 2 * zeta0 * W0 * np.exp(p[1]), p[2], p[3], p[4], p[5],
                         a.real * a_abs, a.imag * a_abs, p[8], p[9] * a_abs, p[10] * a_abs, p[15]])
        return mode, b_abs * np.array([complex(p[11], p[12]), complex(p[13], p[14]), complex(p[16], p[17])])

    def response(pf):
        mode, b = params(pf)
        Z, acc = _rotating_mode(R, Rd, Rm, Rdm, W0, h, mode, q_ref, l_lo, l_hi, z_start, y_start)
        return Z, acc + residual_basis @ b  # residual terms: the other modes' mass or stiffness lines

    weight = ridge * np.sqrt(sel.sum())
    # the residual terms' basis: (w / W0 - 1)^k R for k = 0, 1, 2 in the frame (w R -> W0 R - i R')
    residual_basis = np.stack([R, -1j * Rd / W0, -Rdd / W0**2], axis=1)

    def misfit(pf):
        with np.errstate(all="ignore"):  # a trial step may diverge: a large misfit, not a warning
            res = (response(pf)[1] - Acc)[sel] / peak
        res = np.where(np.isfinite(res) & (np.abs(res) < 1e3), res, 1e3)
        p = np.zeros(18)
        p[free] = pf
        # a ridge on the nuisance terms (the modal constant's slope relative to it, the residual terms
        # relative to the peak): they stay small unless the data ask for them (an impulse-like chirp
        # cannot tell a feedthrough from the mode's response while the drive passes)
        nuisance = np.concatenate([p[9:11] / max(np.hypot(p[6], p[7]), 1e-12),
                                   residual_ridge * np.concatenate([p[11:15], [0.0], p[16:18]])])
        nuisance = nuisance[free[free >= 9] - 9]
        curvature = curv * p[5] * l_lo**2  # the damping's quadratic term's change over the window
        return np.concatenate([res.real, res.imag, weight * nuisance, [weight * curvature]])

    x_scale = np.array([1e-3, 0.1, 0.01, 0.01, 0.2, 0.2, 0.1, 0.1, 0.2, 0.5, 0.5, 0.01, 0.01, 0.01, 0.01, 0.01,
                        0.01, 0.01])
    lower = np.full(18, -np.inf)
    upper = np.full(18, np.inf)
    lower[8], upper[8] = 0.0, 1.0
    norm = np.linalg.norm(Acc[sel] / peak)
    n_res = 2 * int(sel.sum())
    best, rel = None, np.inf
    for f_s, z_s, a_s, b0_s, b1_s, b2_s in _starts(R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0, f0, zeta0, fixed, rot):
        p0 = np.zeros(18)
        p0[:2] = np.log(f_s / f0), np.log(z_s * f_s / (zeta0 * f0))
        a_s = a_s / a_abs / rot
        p0[6], p0[7], p0[8] = a_s.real, (0.0 if fixed else a_s.imag), 0.5
        p0[11:15] = (b0_s.real / b_abs, b0_s.imag / b_abs, b1_s.real / b_abs, b1_s.imag / b_abs)
        p0[16:18] = (b2_s.real / b_abs, b2_s.imag / b_abs)
        sol = least_squares(misfit, p0[free], x_scale=x_scale[free], bounds=(lower[free], upper[free]), max_nfev=100)
        if best is None or sol.cost < best.cost:
            best, rel = sol, float(np.linalg.norm(sol.fun[:n_res]) / norm)  # relative RMS misfit: SweepFit.residual
        if rel < 0.02:  # a good fit: no more starts
            break
    # terms the data must ask for: first the frequency's curvature (a2, a3), by the Bayesian information
    # criterion of the misfit (half the samples counted: the low-passed envelopes are correlated over two);
    # then whether the residual terms (other modes' lines) are needed at all: they must also cut the
    # misfit's sum of squares by the factor `earn`. The single-mode model's own approximation leaves a
    # systematic misfit that any extra term trims a little, and residual terms kept for that bend the
    # backbone (a driving-point force on the Table 3.2 joint at eta 20: they trimmed the misfit by a
    # factor 1.13 and put q_in's frequency +0.21% off, +0.09% without; a second mode's line cuts it 3.6-90x)
    n_eff = n_res / 2

    def refit(keep_free):
        nonlocal free
        p_now = np.zeros(18)
        p_now[free] = best.x
        free = keep_free
        return least_squares(misfit, p_now[free], x_scale=x_scale[free], bounds=(lower[free], upper[free]),
                             max_nfev=60)

    def better(sol_more, sol_less, k, factor):  # do k more parameters earn their place?
        rss_more, rss_less = (float(np.sum(x.fun[:n_res] ** 2)) for x in (sol_more, sol_less))
        return (rss_more > 0 and rss_less > factor * rss_more
                and n_eff * np.log(rss_less / rss_more) > k * np.log(n_eff))

    base_free = free
    trial = refit(np.union1d(free, free_all[np.isin(free_all, (3, 15))]))
    if frequency_curvature == "always" or frequency_curvature == "bic" and better(trial, best, 2, 1.0):
        best = trial
    else:
        free = base_free
    with_b = free
    no_b = free[~np.isin(free, (11, 12, 13, 14, 16, 17))]
    trial = refit(no_b)
    if better(best, trial, with_b.size - no_b.size, earn):
        free = with_b
    else:
        best = trial
    rel = float(np.linalg.norm(best.fun[:n_res]) / norm)
    mode, _ = params(best.x)
    Z, _ = response(best.x)
    q_top = float(np.abs(Z[win]).max())
    coef = (*(float(v) for v in mode[:6]), float(mode[8]), q_ref, l_lo, l_hi, float(mode[11]))
    fit = SweepFit(f_hz=np.nan, zeta=np.nan, q_in=q_top, q_low_in=float(np.abs(Z[win]).min()), residual=rel,
                   coef=coef, modal_constant=complex(mode[6], mode[7]), modal_slope=complex(mode[9], mode[10]),
                   w0=W0, fraction_bad=float(1.0 - win.sum() / max(1, (np.arange(mag.size) >= i0 - i_start).sum())))
    f, z = fit.backbone(q_top)
    return SweepFit(**{**fit.__dict__, "f_hz": float(f), "zeta": float(z)})


def _linear_mode(R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0, f, z, fixed, rot):
    """(misfit norm, A, B_0, B_1, B_2) of a linear mode (f Hz, zeta): its modal constant and residual
    terms by linear least squares (complex; real projections for a fixed phase)."""
    mode = np.array([(2 * np.pi * f) ** 2, 4 * np.pi * f * z, 0, 0, 0, 0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    with np.errstate(all="ignore"):
        x = _rotating_mode(R, Rd, Rm, Rdm, W0, h, mode, 1.0, -1.0, 1.0, 0j, 0j)[1][sel]
    if not np.all(np.isfinite(x)):
        return np.inf, 1.0 + 0j, 0j, 0j, 0j
    cols = np.stack([x, R[sel], -1j * Rd[sel] / W0, -Rdd[sel] / W0**2], axis=1)
    y = Acc[sel]
    if fixed:  # real coefficients of (A e^{-i phase}) x, R, -i R'/W0
        cols = cols * np.array([rot, 1.0, 1.0, 1.0])
        c, *_ = np.linalg.lstsq(np.concatenate([cols.real, cols.imag]), np.concatenate([y.real, y.imag]), rcond=None)
        c = c.astype(complex)
        c[0] = c[0] * rot
    else:
        c, *_ = np.linalg.lstsq(cols, y, rcond=None)
    full = np.stack([x, R[sel], -1j * Rd[sel] / W0, -Rdd[sel] / W0**2], axis=1)
    return float(np.linalg.norm(y - full @ c)), *map(complex, c)


def _starts(R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0, f0, zeta0, fixed, rot, n_keep=3):
    """Start values (f Hz, zeta, A, B_0, B_1, B_2) of the nonlinear fit, lazily: the caller's (f0, zeta0) first; then,
    only if the fit from it is poor, a scan of linear modes over frequencies within +-5% of f0 (or 4
    half-power widths) and damping ratios from zeta0 / 10 to 10 zeta0 (a chirp faster than the mode, or
    a bent peak, can put an FRF's damping a decade off), the n_keep best distinct ones. A and the
    residual terms start from each linear mode's least squares."""
    args = (R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0)
    yield f0, zeta0, *_linear_mode(*args, f0, zeta0, fixed, rot)[1:]
    df = min(0.05, max(4 * zeta0, 0.002))
    rows = [(*_linear_mode(*args, f, z, fixed, rot), f, z)
            for f in f0 * (1 + df * np.linspace(-1, 1, 9)) for z in zeta0 * np.geomspace(0.1, 10.0, 11) if 0 < z < 0.5]
    rows.sort(key=lambda r: r[0])
    kept = [(f0, zeta0)]
    for _, a, b0, b1, b2, f, z in rows:
        if all(abs(f / g - 1) > df / 8 or abs(np.log(z / w)) > 0.3 for g, w in kept):
            kept.append((f, z))
            yield f, z, a, b0, b1, b2
        if len(kept) > n_keep:
            break
