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
   4th-order Butterworth over f (1 -+ `BAND`)); a softening mode moves by a few per cent, well inside
   the band. The filter would smear the forced response before the cut into the decay's first periods
   (on the virtual Ministack +-8% in zeta over its first 7 periods), so the decay is filtered apart,
   preceded by `EXTEND` periods of its own continuation backwards: the damped sinusoid fitted to its
   first window, raw and then once more band-passed, continued from the window's first sample with the
   frequency and decay rate it has there (`_continued`: a softening mode's frequency rises 1% a period
   after the cut from 5 g on the virtual Ministack, and continued at the window centre's frequency
   the junction read the first window 0.05% low, noise-free). The first `SETTLE` period is left out (the
   drive's last sample above `DRIVE_OFF` lies within the DAQ filter's ring after the cut). Where the
   raw first window is not one damped sinusoid (its misfit above `MISFIT_MAX`: other modes ring from
   the start, as after an impact), one mode's continuation would start the others abruptly at the
   junction (a 41 Hz mode 1.5x an 18.6 Hz one: zeta 11% off in its first window), so the whole record
   is band-passed, the first `SETTLE_MIXED` periods left out and the windows start twice as long (an
   18.6 Hz mode with modes at 7 and 41 Hz, 0.5x and 1.5x, from the impact, 18 onset phases: zeta
   within 6.8% from 3 periods, 2.9% from 4, 1.9% from 5; 6-period windows from 3 periods had 7.7%).
3. **Damped sinusoid fits in sliding windows** (`jointcal.measure._decay_window.fit_window`): decay
   rate and frequency at the window's centre, each drifting linearly over it, by variable projection.
   A window is `MIN_CYCLES` periods long while the noise allows; where its decay rate's standard
   error exceeds `ZETA_SE_AIM` of the rate, it grows by `GROW` until the error is met or the window
   spans `SPAN_MAX` e-folds of the decay (a fast decay's amplitude falls by 10% a period, so the
   information a window holds about its rate is bounded by the span of amplitude it covers, not by
   its number of periods). Windows step by half their length. Once all are read, each window is
   fitted again (`REFINE` times) with the third-order terms of its log-envelope and phase held at the
   values its neighbours give (`_cubic_terms`): along a decay the rate and frequency change with the
   amplitude, not linearly in time, and over a long window the log-envelope's t^3 term projects onto its
   slope. On the exact Iwan's Ministack decay from 5 g, noise-free, a window of `SPAN_MAX` e-folds read
   zeta 1.0-2.8% high and f 0.02-0.21% low, and within 0.35% and 0.01% held at the backbone's own third-
   order terms; on a closed-form power-law decay (tests/measure/test_ringdown.py) windows of two e-folds
   read its decay rate 0.5-1.1% high, and within 0.08% held at their neighbours' (the first and last,
   with neighbours on one side, take a slope and no curvature from them: 0.8% and 0.17%).
4. Each window gives ``f_hz`` = w_n / (2 pi) with w_n = sqrt(w^2 + sigma^2) (the undamped natural
   frequency: the damped one is lower by zeta^2 / 2), ``zeta`` = sigma / w_n, and the displacement
   amplitude at its centre ``q_in`` = |a + i b| G / w_n^2 (in; the response in g). Read from the
   acceleration: its envelope decays more slowly than the displacement's by 2 dw/dt / w (a softening
   joint's frequency rises as it decays), and it is this rate that the first-harmonic balance's
   zeta(q) w_n(q) matches (the exact Iwan's Ministack ring-down: acceleration within 0.2-0.6%,
   displacement 1-2% faster; from 5 g, noise-free, the acceleration within 0.1-0.5% and the
   displacement 3-9% faster). The agreement is two effects cancelling, not the slow flow's: a decay
   built on the first-harmonic slow flow itself reads zeta 2-5% low from its acceleration and within
   0.1% from its displacement; the exact decay's displacement falls faster than that slow flow.
5. **The noise floor**: the decay is read while the standard error of the window's decay rate is at
   most `ZETA_SE_MAX` of it, so that three standard errors stay within 3% in zeta. Windows grow towards
   half that (`ZETA_SE_AIM`) where the decay's span allows: a read-out of a hundred windows, each held
   only to 1%, meets a 3.4-sigma window (3%) about once in a few hundred; grown to 0.5% where they can,
   the windows that are still noisier are the last few above the floor. The noise is the
   band-passed record's rms over its last `TAIL` (the decay has died out), or, where the window holds
   more than twice as many independent noise samples as the fit's six parameters, the smaller of that
   and the fit's residual rms corrected for the parameters' degrees of freedom; times sqrt((J^T J)^-1)
   of the fit and sqrt(fs / 2B), since the band-passed noise holds one independent sample in fs / 2B,
   B = 2 BAND f. The windows after the first that misses are dropped and the row of the last kept
   window is flagged ``noise_floor``. A window whose fit residual exceeds `MISFIT_MAX` of its
   amplitude (a beating with a close mode, a clipped start) is flagged ``misfit`` and kept, marked.

Checked against closed forms (tests/measure/test_ringdown.py): a linear mode's decay at 5800x over the noise
gives its f within 8e-5 and zeta within 1.3% over three decades; the exact Iwan simulator's 100 Hz
ring-down the first-harmonic balance backbone within 0.017% and 1.8% over 3.1 decades. The virtual
Ministack at 0.1% noise (tests/synth/test_dwell.py; 2.3 kHz, zeta 1.5% falling to 0.4%, the
amplitude 10% down each period at the start) reads 1.66-2.12 decades per ring-down within 0.062% in
f and 2.9% in zeta (36 decays, six seeds, before the third-order refit), where 6-period windows from
3 periods after the cut had read 0.69-0.80 decades: the noise floor's rule stopped them once a fixed
window's decay rate was noisier than 1%, and the band-pass's smear of the cut cost the first 0.3
decades. Cut from 5 g (tests/benchmarks/accept_testkinds.py, seeds 1-3, 18 decays, 1.65-2.13 decades)
it reads f within 0.039% (before the continuation ran on at the junction's frequency and decay rate:
0.100%, the first window, 2.5 periods after the cut, -0.095 to -0.100%) and zeta within 3.0% with windows
grown only to `ZETA_SE_MAX` (the worst a window of 5 periods whose standard error is 0.87%: a 3.4-sigma
excursion of the noise); grown towards `ZETA_SE_AIM` (2026-11-26, seeds 1-3) f within 0.039% and zeta
within 2.3% over 1.68-1.79 decades (before 1.80-2.04), and the voltage-driven beam's f within 0.021% and
zeta within 2.0% over 1.57-1.63 decades (before 0.032%, 2.2%, 1.54-1.66).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import signal

from ..spectral import DRIVE_OFF, HOLD, drive_end, plateau_end
from ..units import G
from ._decay_window import fit_drifts, fit_window

__all__ = ["decay_start", "ringdown_backbone", "ringdown_at", "slide_windows", "COLUMNS", "DRIVE_OFF", "HOLD", "BAND",
           "ZETA_SE_MAX", "ZETA_SE_AIM", "MISFIT_MAX", "SETTLE", "TAIL", "MIN_CYCLES", "GROW", "SPAN_MAX", "EXTEND", "SETTLE_MIXED"]

BAND = 0.3  # band-pass half-width, relative to the mode's frequency
ZETA_SE_MAX = 0.01  # a window is read while its decay rate's standard error is below this share of it
ZETA_SE_AIM = 0.005  # a window grows (within SPAN_MAX) until its decay rate's standard error is below this share
TAIL = 0.1  # share of the record at its end whose band-passed rms is the noise (the decay has died out)
MISFIT_MAX = 0.05  # relative rms residual of a window fit above which it is not one decaying mode
SETTLE = 1.0  # periods after the decay's start before the first window: the DAQ filter's ring at the cut-off
SETTLE_MIXED = 5.0  # the same where other modes ring from the start: their onsets' ring through the band-pass
MIN_CYCLES = 3.0  # the shortest window, periods of the mode
GROW = 1.25  # a window too short for the noise grows by this factor
SPAN_MAX = 2.0  # a window covers at most this many e-folds of the decay (sigma * length): amplitude / 7.4
EXTEND = 20.0  # periods of the decay's backward continuation ahead of it when band-passing it apart
PARAMS = 6  # the window fit's parameters: a, b, w, sigma and their drifts
REFINE = 2  # refits of every window with the decay's curvature from its neighbours' previous fits
CURVE_SPAN = 2.5  # e-folds of amplitude either side of a window whose windows give the decay's curvature there


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
        With a drive, `jointcal.spectral.drive_end`: one sample after the last at which |drive|
        exceeds DRIVE_OFF of its largest value, unless the response has by then decayed below half
        its plateau (a reference that stays live after the cut: a force gauge on a shaker left
        attached). Else, and without a drive, `jointcal.spectral.plateau_end`: the last sample at
        which the response's envelope (|analytic signal|, smoothed over 50 ms, the record's first
        and last second left out) is within `HOLD` of its plateau (the median of the envelope where
        it exceeds half its largest value): the end of a dwell's steady state, or just after an
        impact's peak.
    """
    if drive is not None:
        end = drive_end(fs, drive, response)
        if end is None:
            raise ValueError("the drive channel is zero throughout: no drive was cut off; give the decay's start.")
    else:
        end = plateau_end(fs, response)[2]
    if end >= len(response) - int(fs):
        raise ValueError("the drive (or the response's steady state) lasts until the record's last second: there is "
                         "no free decay to read; record at least a few seconds after the drive is cut off.")
    return int(end)


def _centred(n: int, fs: float) -> NDArray:
    return (np.arange(n) - (n - 1) / 2) / fs


def _band_passed_decay(x: NDArray, y: NDArray, i0: int, sos, n: int, fs: float, f_hz: float) -> NDArray | None:
    """`y` (the whole record band-passed) with its decay from `i0` on band-passed apart, after `EXTEND`
    periods of its own damped sinusoid continued backwards (fitted to its first `n` samples: raw, then once
    band-passed), so that the filter sees no forced response and no edge at the decay's start; None where the
    raw decay's first window is not one damped sinusoid (its misfit above `MISFIT_MAX`: other modes ring from
    the start, and a continuation of this mode alone would start them abruptly at the junction)."""
    pad = int(round(EXTEND * fs / f_hz))
    src = x
    for k in range(2):
        p, c, misfit = fit_drifts(_centred(n, fs), src[i0:i0 + n], 2 * np.pi * f_hz)
        if k == 0 and misfit > MISFIT_MAX:
            return None
        cont = _continued(p, c, n, pad, fs)
        src = np.concatenate([y[:i0], signal.sosfiltfilt(sos, np.concatenate([cont, x[i0:]]))[pad:]])
    return src


def _continued(p: NDArray, c: complex, n: int, pad: int, fs: float) -> NDArray:
    """The `pad` samples before a window of n samples: its damped sinusoid (`fit_drifts`: p = (w, sigma, r, s) at
    the window's centre, c = a + i b) continued backwards from the window's first sample with the frequency and
    decay rate it has there, so that phase, frequency, amplitude and decay rate run on across the junction (a
    decay whose frequency rises 1% a period, continued at its centre's, is read -0.05% low in its first window)."""
    w, sig, r, s = p
    tj = -(n - 1) / 2 / fs  # the junction, on the window's centred clock
    dt = np.arange(-pad, 0) / fs  # before the junction
    phase = w * tj + 0.5 * r * tj * tj + (w + r * tj) * dt
    env = np.exp(-sig * tj - 0.5 * s * tj * tj - (sig + s * tj) * dt)
    return env * (c.real * np.cos(phase) + c.imag * np.sin(phase))


COLUMNS = ["t_s", "window_s", "q_in", "f_hz", "zeta", "zeta_se", "f_se_hz", "misfit", "flags"]


def _prepared(response_g: NDArray, fs: float, f_hz: float, start: int | None, drive: NDArray | None,
              min_cycles: float) -> tuple[NDArray, int, int, float, float]:
    """Steps 1-2 and the noise of step 5: (y, i0, n, settle, noise).

    y is the record band-passed (its decay apart, `_band_passed_decay`, where it is one mode), i0 the
    decay's first sample, n the shortest window (samples), settle the periods left out after i0, noise
    the band-passed record's rms over its last `TAIL` (its unit)."""
    x = np.nan_to_num(np.asarray(response_g, float))
    if not (np.isfinite(f_hz) and 0 < f_hz * (1 + BAND) < fs / 2):
        raise ValueError(f"the mode's frequency {f_hz!r} Hz must lie below the record's Nyquist frequency {fs / 2:g} Hz.")
    sos = signal.butter(4, [f_hz * (1 - BAND), f_hz * (1 + BAND)], btype="bandpass", fs=fs, output="sos")
    x = x - np.median(x)
    y = signal.sosfiltfilt(sos, x)
    i0 = decay_start(fs, y, drive) if start is None else int(start)
    n = max(16, int(round(min_cycles * fs / f_hz)))
    noise = float(np.sqrt(np.mean(y[-max(n, int(TAIL * y.size)):] ** 2)))  # where the decay has died out
    apart = _band_passed_decay(x, y, i0, sos, n, fs, f_hz) if i0 + n <= y.size else None
    settle = SETTLE
    if apart is None:  # other modes from the start: the whole record band-passed, read after their onsets' ring
        settle, n = SETTLE_MIXED, 2 * n
    else:
        y = apart
    return y, i0, n, settle, noise


def _read_window(y: NDArray, lo: int, n: int, fs: float, f_hz: float, w0: float, sig0: float,
                 noise: float, cubic: tuple[float, float] = (0.0, 0.0)) -> tuple[dict, float, float, float]:
    """Steps 3-5 on one window y[lo:lo + n]: its row (`ringdown_backbone`'s columns, and the private ``_u``,
    ``_w``, ``_sig``: log-amplitude, rad/s, 1/s), w, sigma and sigma's standard error (rad/s, 1/s, 1/s);
    `cubic` the known third-order terms of its phase and log-envelope (`_cubic_terms`)."""
    per_sample = np.sqrt(fs / (4 * BAND * f_hz))  # one independent noise sample in fs / 2B
    w, sig, c, res, se_sig, se_w = fit_window(_centred(n, fs), y[lo:lo + n], w0, sig0, cubic=cubic)
    n_eff = n / per_sample**2
    window_noise = noise  # the tail; the residual too where it holds enough independent samples
    if n_eff > 2 * PARAMS:
        window_noise = min(noise, res * abs(c) / np.sqrt(2) / np.sqrt(1 - PARAMS / n_eff))
    se_sig *= window_noise * per_sample
    se_w *= window_noise * per_sample
    wn = float(np.hypot(w, sig))
    row = dict(t_s=(lo + (n - 1) / 2) / fs, window_s=n / fs, q_in=abs(c) * G / wn**2, f_hz=wn / (2 * np.pi),
               zeta=sig / wn, zeta_se=se_sig / wn, f_se_hz=se_w / (2 * np.pi), misfit=res,
               flags="misfit" if res > MISFIT_MAX else "", _u=float(np.log(max(abs(c), 1e-300))), _w=w, _sig=sig)
    return row, w, sig, se_sig


def _refined(y: NDArray, rows: list[dict], fs: float, f_hz: float, noise: float) -> list[dict]:
    """`rows` refitted `REFINE` times, each window with the third-order terms its neighbours give
    (`_cubic_terms`); flags kept."""
    for _ in range(REFINE if len(rows) >= 3 else 0):
        new = []
        for row, cubic in zip(rows, _cubic_terms(rows)):
            n = int(round(row["window_s"] * fs))
            lo = int(round(row["t_s"] * fs - (n - 1) / 2))
            r, *_ = _read_window(y, lo, n, fs, f_hz, row["_w"], row["_sig"], noise, cubic)
            r["flags"] = ";".join(dict.fromkeys(filter(None, (r["flags"] + ";" + row["flags"]).split(";"))))
            new.append(r)
        rows = new
    return rows


def _cubic_terms(rows: list[dict]) -> list[tuple[float, float]]:
    """Each window's third-order phase and log-envelope terms (rad/s^3, 1/s^3), from the decay's backbone as
    its windows read it: sigma(u) and w(u) against the log-amplitude u, a weighted quadratic over the
    windows within `CURVE_SPAN` e-folds of each (none where fewer than three span half an e-fold; a straight
    line where they all lie on one side: the decay's first and last windows).

    Along a free decay du/dt = -sigma(u), so d3u/dt3 = -sigma (sigma_uu sigma + sigma_u^2), and the phase's
    d2w/dt2 = w_uu sigma^2 + w_u sigma_u sigma; a window's model (`fit_window`) holds them as t^3 terms,
    a sixth of each, fixed.
    """
    U = np.array([r["_u"] for r in rows])
    S = np.array([r["_sig"] for r in rows])
    W = np.array([r["_w"] for r in rows])
    wt = np.array([1.0 / max(r["zeta_se"] * np.hypot(r["_w"], r["_sig"]), 1e-300) ** 2 for r in rows])
    wt[~(np.isfinite(wt) & np.isfinite(S) & np.isfinite(W) & (S > 0))] = 0.0
    out = []
    for u, sig in zip(U, S):
        d = U - u
        sel = (np.abs(d) <= CURVE_SPAN) & (wt > 0)
        if not sig > 0 or sel.sum() < 3 or np.ptp(d[sel]) < 0.5:
            out.append((0.0, 0.0))
            continue
        deg = 2 if d[sel].min() < 0 < d[sel].max() else 1  # at either end of the decay, no curvature extrapolated
        A = np.column_stack([d[sel] ** j for j in range(deg + 1)]) * np.sqrt(wt[sel])[:, None]
        (_, s_u, s_uu), (_, w_u, w_uu) = (np.r_[np.linalg.lstsq(A, v[sel] * np.sqrt(wt[sel]), rcond=None)[0], 0.0][:3]
                                          * [1, 1, 2] for v in (S, W))
        out.append(((w_uu * sig**2 + w_u * s_u * sig) / 6, -sig * (s_uu * sig + s_u**2) / 6))
    return out


def ringdown_backbone(response_g: NDArray, fs: float, f_hz: float, *, start: int | None = None,
                      drive: NDArray | None = None, min_cycles: float = MIN_CYCLES) -> pd.DataFrame:
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
    min_cycles : float
        The shortest window, periods of the mode (windows grow where the noise asks for it).

    Returns
    -------
    DataFrame
        One row per window, in time order: ``t_s`` (window centre, s from the record's start),
        ``window_s`` (its length, s), ``q_in`` (displacement amplitude, in), ``f_hz`` (undamped natural
        frequency, Hz), ``zeta``, ``zeta_se`` and ``f_se_hz`` (their standard errors from the noise; Hz),
        ``misfit`` (relative rms residual), ``flags`` (``noise_floor`` on the last row read, ``misfit``).
    """
    y, i0, n, settle, noise = _prepared(response_g, fs, f_hz, start, drive, min_cycles)

    def read(lo, n, w0, sig0):
        row, w, sig, se_sig = _read_window(y, lo, n, fs, f_hz, w0, sig0, noise)
        return row, w, sig, se_sig / sig if sig > 0 else np.inf, True

    rows = slide_windows(read, y.size, i0 + int(round(settle * fs / f_hz)), n, 2 * np.pi * f_hz, fs, ZETA_SE_MAX,
                         ZETA_SE_AIM)
    return pd.DataFrame(_refined(y, rows, fs, f_hz, noise), columns=COLUMNS)


def slide_windows(read, size: int, lo: int, n: int, w0: float, fs: float, se_max: float,
                  se_aim: float | None = None) -> list[dict]:
    """The windows along a decay (step 3 of the module's text): from sample lo, windows of n samples at first,
    each grown by `GROW` while its damping's relative standard error exceeds se_max (until it spans `SPAN_MAX`
    e-folds), stepping by half their length, and stopped at the first that misses (its predecessor flagged
    ``noise_floor``); windows missing before the first is read are stepped over (the loud start).

    Parameters
    ----------
    read : callable
        ``read(lo, n, w0, sig0) -> (row, w, sig, rel_se, ok)``: the window of n samples from lo, started at the
        previous window's frequency w0 (rad/s) and decay rate sig0 (1/s); its row (a dict with ``flags``), its
        frequency w and decay rate sig, zeta's relative standard error rel_se, and whether the read is usable.
        `forced_decay` reads through the force with the same rule.
    size : int
        Samples in the record.
    lo, n : int
        The first window's start and length, samples.
    w0 : float
        The mode's approximate frequency, rad/s.
    fs : float
        Sample rate, Hz.
    se_max : float
        The largest relative standard error of a window's damping read.
    se_aim : float, optional
        The relative standard error a window grows towards (within `SPAN_MAX` e-folds); default se_max.

    Returns
    -------
    list of dict
        The windows' rows, in time order.
    """
    rows, sig0 = [], 0.0
    se_aim = se_max if se_aim is None else se_aim
    while lo + n <= size:
        row, w, sig, rel_se, ok = read(lo, n, w0, sig0)
        good = ok and sig > 0 and 0.5 * w0 < w < 1.5 * w0
        longer = int(n * GROW) + 1
        if good and rel_se > se_aim and sig * longer / fs <= SPAN_MAX and lo + longer <= size:
            n = longer  # too short for the noise: the same start, a longer window
            continue
        if not (good and rel_se <= se_max):
            if not rows:  # not yet read: the loud start (the joint's distortion in the residual) may be past
                lo += max(1, n // 2)
                continue
            rows[-1]["flags"] = ";".join(filter(None, [rows[-1]["flags"], "noise_floor"]))
            break
        rows.append(row)
        w0, sig0 = w, sig
        lo += max(1, n // 2)
    return rows


def ringdown_at(response_g: NDArray, fs: float, f_hz: float, windows: pd.DataFrame, *, start: int | None = None,
                drive: NDArray | None = None, min_cycles: float = MIN_CYCLES) -> pd.DataFrame:
    """`ringdown_backbone`'s read-out of a decay at given windows: another record read where one was read.

    The same band-pass, start and window fit (steps 1-5), each window of `windows` (its ``t_s`` centre and
    ``window_s`` length) fitted as it stands, then again with the third-order terms its neighbours among
    `windows` give: no growing, no noise-floor stop. A model's decay read at the measured decay's windows
    carries the same window-length bias (what the refit leaves of it), which then cancels in a comparison.

    Parameters
    ----------
    response_g, fs, f_hz, start, drive, min_cycles
        As `ringdown_backbone`.
    windows : DataFrame
        ``t_s`` (window centre, s from the record's start) and ``window_s`` (s), e.g. `ringdown_backbone`'s
        rows of another record of the same length and sample rate.

    Returns
    -------
    DataFrame
        `ringdown_backbone`'s columns, one row per window of `windows` in its order (flags: ``misfit`` only).
    """
    y, _, _, _, noise = _prepared(response_g, fs, f_hz, start, drive, min_cycles)
    w0, sig0, rows = 2 * np.pi * f_hz, 0.0, []
    for t_c, length in zip(windows["t_s"].to_numpy(float), windows["window_s"].to_numpy(float)):
        n = int(round(length * fs))
        lo = int(round(t_c * fs - (n - 1) / 2))
        if lo < 0 or lo + n > y.size:
            raise ValueError(f"a window centred at {t_c:g} s, {length:g} s long, lies outside the record "
                             f"({y.size / fs:g} s); read windows of a record as long as this one.")
        row, w, sig, _ = _read_window(y, lo, n, fs, f_hz, w0, sig0, noise)
        rows.append(row)
        if sig > 0 and 0.5 * w0 < w < 1.5 * w0:
            w0, sig0 = w, sig
    return pd.DataFrame(_refined(y, rows, fs, f_hz, noise), columns=COLUMNS)
