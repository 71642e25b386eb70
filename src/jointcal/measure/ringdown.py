"""Amplitude-dependent frequency and damping along a free decay (a ring-down).

After an impact, or after a shaker's drive is cut off from a steady dwell, a jointed mode rings down
through the amplitudes its joint slipped at. Read along the decay, one record gives the backbone over
the decades of amplitude it spans: the paper's eq. 3.9 takes frequency and damping "estimated with
either swept sine or transient ring-down tests".

The estimator (``ringdown_backbone``), in the order data flows:

1. **Where the decay starts** (``decay_start``): the last sample at which the drive exceeds
   `DRIVE_OFF` of its largest value (a drive cut to zero); without a drive channel, the last sample
   at which the band-passed response's envelope lies within `HOLD` of its plateau (the end of a
   dwell's steady state, or just after an impact's peak).
2. **One mode**: the response is band-passed around the mode, zero phase (`scipy.signal.sosfiltfilt`,
   4th-order Butterworth over f (1 -+ `BAND`)), over the whole record, so the decay's start is no edge of
   the filter; a softening mode moves by a few per cent, well inside the band. The first `SETTLE` periods
   after the cut-off are left out: the filter's response to the cut itself (a linear decay read from the
   cut: f -0.5%, zeta -60% in the first window).
3. **Damped sinusoid fits in sliding windows** of `cycles` periods, stepping by half a window:
   x(t) = exp(-sigma t) (a cos w t + b sin w t) by least squares, w and sigma by Gauss-Newton, a and b by
   variable projection. Unlike the Hilbert transform's instantaneous amplitude and phase, a window fit
   has no end effects to trim and averages the noise over the window; its frequency and decay rate are
   those of the window's mean amplitude (the decay's envelope changes by exp(-2 pi zeta cycles) over a
   window: 6% at zeta = 0.01 and 6 cycles, whose curvature biases the read-out by less than 0.1%).
4. Each window gives ``f_hz`` = w_n / (2 pi) with w_n = sqrt(w^2 + sigma^2) (the undamped natural
   frequency: the damped one is lower by zeta^2 / 2), ``zeta`` = sigma / w_n, and the displacement
   amplitude at its centre ``q_in`` = |a + i b| exp(-sigma t_c) G / w_n^2 (in; the response in g).
5. **The noise floor**: the decay is read while the standard error of the window's decay rate that
   the noise gives (the smaller of two upper bounds of the noise: the band-passed record's rms over
   its last `TAIL`, where the decay has died out, and the window fit's residual rms, which also holds
   the model's error; times sqrt((J^T J)^-1) of the fit and sqrt(fs / 2B), since the band-passed noise holds one
   independent sample in fs / 2B, B = 2 BAND f) is at most `ZETA_SE_MAX` of it, so
   that three standard errors stay within 3% in zeta (a linear decay at zeta = 0.5% under noise:
   per-window errors of 1-2% where the decay stands 80-2000x over the noise's rms, 13% at 10-20x, which
   an amplitude threshold alone would have kept); the windows after are dropped and the row of the
   last kept window is flagged ``noise_floor``. A window whose fit residual exceeds `MISFIT_MAX` of its amplitude (a beating with a
   close mode, a clipped start) is flagged ``misfit`` and kept, marked.

Checked against closed forms (tests/measure/test_ringdown.py): a linear mode's decay gives its f and
zeta to 1e-5 and 1e-3; the exact Iwan simulator's ring-down gives the first-harmonic balance backbone
within 0.1% and 3% over 1.5 decades of amplitude.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import signal

from ..units import G

__all__ = ["decay_start", "ringdown_backbone", "DRIVE_OFF", "HOLD", "BAND", "ZETA_SE_MAX", "MISFIT_MAX", "SETTLE", "TAIL"]

DRIVE_OFF = 0.02  # a drive below this share of its largest value is off
HOLD = 0.05  # without a drive: the decay starts where the envelope last lies within this share of its plateau
BAND = 0.3  # band-pass half-width, relative to the mode's frequency
ZETA_SE_MAX = 0.01  # a window is read while its decay rate's standard error is below this share of it
TAIL = 0.1  # share of the record at its end whose band-passed rms is the noise (the decay has died out)
MISFIT_MAX = 0.05  # relative rms residual of a window fit above which it is not one decaying mode
SETTLE = 3.0  # periods after the cut-off before the first window: the band-pass filter's response to the cut


def decay_start(fs: float, response: NDArray, drive: NDArray | None = None) -> int:
    """Index of the first sample of the free decay.

    Parameters
    ----------
    fs : float
        Sample rate, Hz.
    response : ndarray, shape (n,)
        The response, band-passed around the mode (any unit).
    drive : ndarray, shape (n,), optional
        The drive (any unit); None for an impact, or a dwell whose drive was not recorded.

    Returns
    -------
    int
        With a drive, one sample after the last at which |drive| exceeds DRIVE_OFF of its largest
        value; without, the last sample at which the response's envelope (|analytic signal|, smoothed
        over 50 ms, the record's first and last second left out) is within `HOLD` of its plateau (the
        median of the envelope where it exceeds half its largest value): the end of a dwell's steady
        state, or just after an impact's peak.
    """
    if drive is not None:
        d = np.abs(np.nan_to_num(np.asarray(drive, float)))
        on = np.flatnonzero(d > DRIVE_OFF * d.max()) if d.max() > 0 else np.empty(0, int)
        if on.size == 0:
            raise ValueError("the drive channel is zero throughout: no drive was cut off; give the decay's start.")
        end = on[-1] + 1
    else:
        env = np.abs(signal.hilbert(np.nan_to_num(np.asarray(response, float))))
        env = np.convolve(env, np.ones(max(1, int(0.05 * fs))) / max(1, int(0.05 * fs)), "same")
        edge = min(int(fs), env.size // 8)  # the band-pass filter's and the transform's own edges
        core = env[edge:env.size - edge]
        plateau = np.median(core[core >= 0.5 * core.max()])  # a dwell's steady level (its start may overshoot)
        end = edge + int(np.flatnonzero(core >= (1 - HOLD) * plateau)[-1])
    if end >= len(response) - int(fs):
        raise ValueError("the drive (or the response's steady state) lasts until the record's last second: there is "
                         "no free decay to read; record at least a few seconds after the drive is cut off.")
    return int(end)


def _fit_window(t: NDArray, x: NDArray, w0: float) -> tuple[float, float, complex, float, float]:
    """Fit x ~ exp(-sigma t) (a cos wt + b sin wt), t centred on the window.

    Returns w, sigma, a + i b, the relative rms residual and the standard error of sigma per unit
    white-noise rms (sqrt of (J^T J)^-1's sigma entry, over the four parameters).
    """
    w, sig = w0, 0.0
    for _ in range(30):
        e = np.exp(-sig * t)
        B = np.column_stack([e * np.cos(w * t), e * np.sin(w * t)])
        (a, b), *_ = np.linalg.lstsq(B, x, rcond=None)
        r = x - B @ [a, b]
        J = np.column_stack([e * t * (-a * np.sin(w * t) + b * np.cos(w * t)), -t * (B @ [a, b])])
        step, *_ = np.linalg.lstsq(J, r, rcond=None)
        w, sig = w + step[0], sig + step[1]
        if abs(step[0]) < 1e-10 * w and abs(step[1]) < 1e-9 * w:
            break
    e = np.exp(-sig * t)
    B = np.column_stack([e * np.cos(w * t), e * np.sin(w * t)])
    (a, b), *_ = np.linalg.lstsq(B, x, rcond=None)
    r = x - B @ [a, b]
    J = np.column_stack([e * t * (-a * np.sin(w * t) + b * np.cos(w * t)), -t * (B @ [a, b]), B])
    try:
        se_sigma = float(np.sqrt(np.linalg.inv(J.T @ J)[1, 1]))
    except np.linalg.LinAlgError:
        se_sigma = np.inf
    res = float(np.sqrt(np.mean(r**2)) / max(np.hypot(a, b) / np.sqrt(2), 1e-300))
    return float(w), float(sig), complex(a, b), res, se_sigma


def ringdown_backbone(response_g: NDArray, fs: float, f_hz: float, *, start: int | None = None,
                      drive: NDArray | None = None, cycles: float = 6.0) -> pd.DataFrame:
    """Frequency and damping of one mode along its free decay, against its amplitude.

    Parameters
    ----------
    response_g : ndarray, shape (n,)
        Response acceleration, g (NaN samples count as zero; flag the run elsewhere).
    fs : float
        Sample rate, Hz.
    f_hz : float
        The mode's approximate frequency, Hz (within BAND / 2 of its frequency along the decay).
    start : int, optional
        First sample of the decay; default `decay_start` (from `drive` when given).
    drive : ndarray, shape (n,), optional
        The drive channel, to find where it was cut off.
    cycles : float
        Window length in periods of the mode.

    Returns
    -------
    DataFrame
        One row per window, in time order: ``t_s`` (window centre, s from the record's start),
        ``q_in`` (displacement amplitude, in), ``f_hz`` (undamped natural frequency, Hz), ``zeta``,
        ``zeta_se`` (its standard error), ``misfit`` (relative rms residual), ``flags`` (``noise_floor`` on the last row read,
        ``misfit``).
    """
    x = np.nan_to_num(np.asarray(response_g, float))
    if not (np.isfinite(f_hz) and 0 < f_hz * (1 + BAND) < fs / 2):
        raise ValueError(f"the mode's frequency {f_hz!r} Hz must lie below the record's Nyquist frequency {fs / 2:g} Hz.")
    sos = signal.butter(4, [f_hz * (1 - BAND), f_hz * (1 + BAND)], btype="bandpass", fs=fs, output="sos")
    y = signal.sosfiltfilt(sos, x - np.median(x))
    i0 = decay_start(fs, y, drive) if start is None else int(start)
    n_win = max(16, int(round(cycles * fs / f_hz)))
    noise = float(np.sqrt(np.mean(y[-max(n_win, int(TAIL * y.size)):] ** 2)))  # where the decay has died out
    w0 = 2 * np.pi * f_hz
    rows = []
    settle = int(round(SETTLE * fs / f_hz))  # the band-pass's own ring at the cut-off
    for lo in range(i0 + settle, y.size - n_win, max(1, n_win // 2)):
        t = (np.arange(n_win) - (n_win - 1) / 2) / fs
        w, sig, c, res, se_sig = _fit_window(t, y[lo:lo + n_win], w0)
        window_noise = min(noise, res * abs(c) / np.sqrt(2))  # each an upper bound: the tail, the fit's residual
        se_sig *= window_noise * np.sqrt(fs / (4 * BAND * f_hz))  # one independent noise sample in fs / 2B
        wn = float(np.hypot(w, sig))
        if not (sig > 0 and se_sig <= ZETA_SE_MAX * sig and 0.5 * w0 < w < 1.5 * w0):
            if not rows:  # not yet read: the loud start (the joint's distortion in the residual) may be past
                continue
            rows[-1]["flags"] = ";".join(filter(None, [rows[-1]["flags"], "noise_floor"]))
            break
        rows.append(dict(t_s=(lo + (n_win - 1) / 2) / fs, q_in=abs(c) * G / wn**2, f_hz=wn / (2 * np.pi),
                         zeta=sig / wn, zeta_se=se_sig / wn, misfit=res, flags="misfit" if res > MISFIT_MAX else ""))
        w0 = w
    return pd.DataFrame(rows, columns=["t_s", "q_in", "f_hz", "zeta", "zeta_se", "misfit", "flags"])
