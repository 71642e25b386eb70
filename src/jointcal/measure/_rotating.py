"""One amplitude-dependent mode in a frame rotating at a fixed frequency, and the signals it is compared with.

Private: `jointcal.measure.sweepfit` fits this model. `rotating_mode` integrates

    Z'' + (2 i W_0 + c) Z' + (Omega^2 - W_0^2 + i (c W_0 + phi D Omega)) Z = A_0 R - i A_1 R' / W_0

by RK4 (numba); `baseband` demodulates a record into the frame; `bridge` carries a swept
drive's envelope across bad samples; `fit_window` picks the samples fitted; `demodulate`
and `passage` make the signals the fit compares, cut to the passage through the mode.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray
from scipy import signal

from ..units import G

__all__ = ["rotating_mode", "baseband", "dilate", "bridge", "fit_window", "Signals", "demodulate", "Passage", "passage",
           "head_end"]


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
def rotating_mode(r, rd, rm, rdm, w0, h, p, q_ref, l_lo, l_hi, z0, y0):
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


def dilate(bad: NDArray[np.bool_], n: int) -> NDArray[np.bool_]:
    """bad widened by n samples on each side."""
    if n <= 0 or not bad.any():
        return bad
    return np.convolve(bad.astype(float), np.ones(2 * n + 1), mode="same") > 0.5


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """[start, stop) of each run of True in mask."""
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def bridge(x: NDArray, bad: NDArray[np.bool_]) -> NDArray:
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


def fit_window(mag: NDArray, ok: NDArray[np.bool_], frac: float, quiet: float,
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


@dataclass(frozen=True)
class Signals:
    """The drive's envelope R (with its rates Rd, Rdd and RK4 midpoints Rm, Rdm) and the response's
    acceleration envelope Acc in the frame rotating at W0 (rad/s), on the RK4 grid of step h (s); the
    record's first sample at step `first` (zeros before it) and the low-pass's reach, `reach` steps."""

    R: NDArray
    Rd: NDArray
    Rdd: NDArray
    Rm: NDArray
    Rdm: NDArray
    Acc: NDArray
    ok: NDArray
    h: float
    W0: float
    first: int = 0
    reach: int = 0


def demodulate(ref: NDArray, resp_g: NDArray, fs: float, f0: float, zeta0: float, cutoff: float,
                steps_per_cycle: float) -> Signals:
    """The record demodulated at f0, low-passed at cutoff f0, on the RK4 grid; bad samples bridged or marked."""
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
    bad_R, bad_A = dilate(bad_r, margin), dilate(bad_a, margin)
    up = int(np.ceil(2 * steps_per_cycle * f0 / fs))  # a record sampled under 2 x 6 per cycle: the
    if up > 1:                                       # envelopes (band-limited below cutoff f0) upsampled
        R, Acc = (signal.resample_poly(x.real, up, 1) + 1j * signal.resample_poly(x.imag, up, 1) for x in (R, Acc))
        bad_R, bad_A = np.repeat(bad_R, up), np.repeat(bad_A, up)
    fs_b = fs * up
    half = max(1, int(round(fs_b / (2 * steps_per_cycle * f0))))  # samples per RK4 half step
    h = 2 * half / fs_b
    Rh = R[::half]  # the drive at every half step: RK4's midpoints see it exactly, not interpolated
    Rh = bridge(Rh, bad_R[::half])
    Rdh = np.gradient(Rh, h / 2)
    Rddh = np.gradient(Rdh, h / 2)
    R = Rh[::2]
    Acc, bad_A = Acc[::2 * half][:R.size], bad_A[::2 * half][:R.size]
    return Signals(R=R, Rd=Rdh[::2], Rdd=Rddh[::2], Rm=Rh[1::2], Rdm=Rdh[1::2], Acc=Acc, ok=~bad_A, h=h, W0=W0,
                   first=int(round(margin * up / (2 * half))), reach=int(np.ceil(margin * up / (2 * half))))


def head_end(sig: Signals) -> int:
    """The step a low-pass reach into the record (past the smear of the zeros before it)."""
    return min(sig.first + sig.reach, sig.R.size - 1)


@dataclass(frozen=True)
class Passage:
    """The signals cut to the passage through the mode, the samples fitted (`sel`, `win`: all good ones in
    the window), the window itself (`inside`, bad samples too: the model's response is defined there),
    the integration's start state (z_start, y_start, at step `i_start` of the signals; `free_start`:
    the record began with the mode already moving, so the state is fitted from there), the share of
    the window left out and whether the record ended ringing (`ringing_end`: the window runs to the
    record's last sample, its free decay cut)."""

    sig: Signals
    sel: NDArray
    win: NDArray
    inside: NDArray
    z_start: complex
    y_start: complex
    fraction_bad: float
    ringing_end: bool = False
    free_start: bool = False
    i_start: int = 0


def passage(sig: Signals, window: float, quiet: float, steps_per_cycle: float, free_start: bool = False) -> Passage:
    """The stretch fitted (`jointcal.measure._rotating.fit_window`) and the forced state it starts from.

    free_start: where the integration would start from rest at the record's start, start it a low-pass
    reach into the record (past the smear of the zeros before it) from a state to be fitted instead
    (a record that begins with the mode already moving: `jointcal.measure.sweepfit`).
    """
    mag = np.abs(sig.Acc)
    i_start, i0, i1 = fit_window(mag, sig.ok, window, quiet)
    free_start = bool(free_start and i_start == 0 and 0 < head_end(sig) < i1 and sig.ok[head_end(sig)])
    if free_start:  # the window's samples before it (in the zeros' smear) are left out
        i_start = head_end(sig)
    R, Rd, Rdd, Acc, ok, mag = (x[i_start:i1 + 1] for x in (sig.R, sig.Rd, sig.Rdd, sig.Acc, sig.ok, mag))
    cut = Signals(R=R, Rd=Rd, Rdd=Rdd, Rm=sig.Rm[i_start:i1], Rdm=sig.Rdm[i_start:i1], Acc=Acc, ok=ok, h=sig.h,
                   W0=sig.W0, first=max(sig.first - i_start, 0), reach=sig.reach)
    inside = np.arange(mag.size) >= i0 - i_start
    win = ok & inside
    # the misfit on every third step (2 samples per cycle at f0): the envelopes are band-limited below
    # cutoff f0, so this loses nothing and cuts the least-squares algebra threefold
    sel = win & (np.arange(mag.size) % max(1, int(steps_per_cycle // 2)) == 0)
    if sel.sum() < 16:
        raise ValueError("the response's passage through the mode holds too few good samples to fit.")
    # the forced state at the start: displacement -Acc / w^2 at the local frequency w = W0 + arg rate
    W0, h = sig.W0, sig.h
    if i_start > 0 and ok[0]:
        w_loc = W0 + float(np.angle(Acc[1] / Acc[0])) / h if abs(Acc[0]) > 0 else W0
        w_loc = min(max(w_loc, 0.3 * W0), 3.0 * W0)
        z_start = complex(-Acc[0] / w_loc**2)
        y_start = complex(1j * (w_loc - W0) * z_start)
    else:
        z_start = y_start = 0j
    return Passage(sig=cut, sel=sel, win=win, inside=inside, z_start=z_start, y_start=y_start,
                    fraction_bad=float(1.0 - win.sum() / max(1, inside.sum())),
                    ringing_end=bool(i1 == sig.Acc.size - 1), free_start=free_start,
                    i_start=int(i_start))
