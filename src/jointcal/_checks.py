"""Checks of one run record against its manifest row (`validate_run`, re-exported by `jointcal.io`).

Also the drive frequency of a short window; clipping is found by `jointcal._clipping`
(its `clip_levels` and `clipped_mask` are re-exported here).
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from jointcal._amplitudes import level_problems, swap_problem, window_amplitudes
from jointcal._clipping import clip_levels, clipped_mask
from jointcal._contract import (
    FS_RTOL, LEVEL, MIN_CYCLES, REFERENCE, RESPONSE, TIME, CampaignError, CampaignWarning, OnDataProblem,
    excitation_of, fail,
)

__all__ = ["validate_run", "clipped_mask", "clip_levels", "window_amplitudes", "time_resolution", "UNUSABLE_FLAGS"]

TIME_UNITS = {"milliseconds": 1e-3, "microseconds": 1e-6, "minutes": 60.0}  # unit -> its size in s
# ingest flags whose run must not enter a calibration: its amplitudes or channels are wrong, or
# it is clipped (a linear SDOF clipped at 95-60 % of its resonance peak gives damping 14-138 %
# high even with the frames touching clipped samples left out: the peak itself is missing)
UNUSABLE_FLAGS = ("level", "units", "swapped", "constant", "clipped")
JITTER = 0.02  # samples further than this many steps off a uniform grid (beyond the times' rounding) are jitter
HEAD_LEVEL = 0.1  # a head quieter than this fraction of the reference's amplitude is silent


def peak_frequency(x: NDArray[np.float64], fs: float, *, pad: int = 16) -> float:
    """Frequency of the largest spectral peak of a short record (Hz).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        Short record (any unit); non-finite samples are treated as 0.
    fs : float
        Sample rate (Hz).
    pad : int, optional
        Zero-padding factor of the FFT (the peak is then refined by a parabola
        through the three highest bins of the log magnitude).

    Returns
    -------
    float
        Peak frequency (Hz) of the Hann-windowed, mean-removed record. For a
        linear chirp this is the instantaneous frequency at the record's centre.
    """
    y = np.nan_to_num(np.asarray(x, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    y = (y - y.mean()) * np.hanning(y.size)
    nfft = pad * y.size
    mag = np.abs(np.fft.rfft(y, nfft))
    mag[: pad + 1] = 0.0  # ignore DC and the first bin: the record is mean-removed
    k = int(np.argmax(mag))
    if 0 < k < mag.size - 1 and mag[k] > 0:
        a, b, c = np.log(mag[k - 1 : k + 2] + 1e-300)
        den = a - 2 * b + c
        k = k + (0.5 * (a - c) / den if den < 0 else 0.0)
    return float(k * fs / nfft)


def _count(k: int, noun: str) -> str:
    return f"{k} {noun}" + ("" if k == 1 else "s")


def validate_run(df: pd.DataFrame, row: Mapping[str, Any], path: str | os.PathLike[str], *,
                 clip_run: int = 3, on_data_problem: OnDataProblem = "error") -> dict[str, Any]:
    """Check one run record against its manifest row.

    Parameters
    ----------
    df : pandas.DataFrame
        The record as returned by `read_run` (its ``attrs['sources']`` name the
        response's declared unit in messages).
    row : mapping
        Its manifest row (see `read_manifest`).
    path : path-like
        The record's file, named in messages.
    clip_run : int, optional
        Fewest samples at a channel's maximum or minimum (within one quantisation
        step) that count as clipping, flat tops of any length (see `clip_levels`).
    on_data_problem : {'error', 'flag'}, optional
        What to do with data problems (NaN/inf values, a constant channel, clipping,
        swapped channels, a reference amplitude off the manifest's level, a base-driven
        response in other units than declared): raise, or
        record them in ``flags`` and emit a `CampaignWarning` with the same sentence.
        Structural problems always raise.

    Returns
    -------
    dict
        ``n_samples``; ``duration_s`` (n / fs, s); ``fs_measured_hz`` (Hz);
        ``excitation`` ('base', 'force' or 'voltage'); ``rms_base_accel_g`` (g),
        ``rms_force_lbf`` (lbf), ``rms_drive_V`` (V), ``rms_response_accel_g`` (g)
        (NaN for the absent references); ``f_first_hz`` and ``f_last_hz``, the drive frequency measured in
        a short window at the record's start and at the sweep's expected end time
        (which a free-decay tail may follow), each referred to that instant with the
        manifest's sweep rate (Hz); ``f_tolerance_hz``, the allowed deviation from
        ``f_start_hz``/``f_stop_hz`` (Hz) (the three NaN when the reference holds no
        signal); ``flags``, a list such as ``['nonfinite:response_accel_g',
        'clipped:base_accel_g']``; the words are ``nonfinite``, ``constant``,
        ``clipped``, ``swapped``, ``level`` and ``units`` (see `UNUSABLE_FLAGS`).

    Raises
    ------
    CampaignError
        Wrong columns or excitation kind, too few samples, non-finite or
        non-increasing or gapped or jittered time (see `time_resolution`), sample
        rate off the manifest by > 0.1 %, a record shorter than 95 % of the sweep, a
        start or end drive frequency off the manifest band by more than
        ``f_tolerance_hz`` (named as a silent pre-trigger head when the record fits
        the band from the drive's onset on); with
        ``on_data_problem='error'`` also the data problems.

    Notes
    -----
    Each window spans ``W = max(20 / f_low, sqrt(2 / rate))`` (at least 20 cycles of
    the lowest frequency; the sqrt balances sweep and resolution), at most a quarter
    of the sweep. The tolerance is ``rate * W / 2 + 1 / W``: the frequency swept
    within half the window plus one FFT bin.

    The amplitude checks (swapped columns, the reference against the manifest's level,
    a base-driven response's units) are `jointcal._amplitudes`'; swapped columns are
    looked for before the band, whose drive is then the response column.

    Time samples more than ``JITTER`` (2 %) of a step off the best uniform grid,
    beyond the rounding of the way the times were written, are jitter.
    """
    if on_data_problem not in ("error", "flag"):
        raise ValueError(f"on_data_problem must be 'error' or 'flag', got {on_data_problem!r}")
    run = repr(row["run_id"])
    kind = excitation_of([str(c) for c in df.columns], path)
    want = next((k for k, c in LEVEL.items() if c in row), "base")
    if kind != want:
        fail(path, f"it holds {REFERENCE[kind]} but the manifest gives {LEVEL[want]} for run {run}",
             f"export {REFERENCE[want]} or correct the manifest's level column")
    t = df[TIME].to_numpy(np.float64)
    ref = REFERENCE[kind]
    chans = {c: df[c].to_numpy(np.float64) for c in (ref, RESPONSE)}
    f0, f1, rate = float(row["f_start_hz"]), float(row["f_stop_hz"]), float(row["sweep_rate_hz_per_s"])
    fs = _check_time(t, float(row["sample_rate_hz"]), path, run)
    sweep_s = abs(f1 - f0) / rate
    band = f"{f0:g} -> {f1:g} Hz at {rate:g} Hz/s"
    if t.size / fs < 0.95 * sweep_s:
        fail(path, f"the record lasts {t.size / fs:.4g} s but the manifest band {band} needs {sweep_s:.4g} s",
             f"check f_start_hz, f_stop_hz and sweep_rate_hz_per_s of run {run} or export the whole record")

    flags: list[str] = []
    drop = f"or remove run {run} from manifest.csv"
    _report(_data_problems(t, chans, clip_run, path, run), flags, on_data_problem)
    silent = {f.split(":", 1)[1] for f in flags if f.split(":", 1)[0] == "constant"}
    silent |= {c for c, x in chans.items() if not np.isfinite(x).any()}
    amp = {c: window_amplitudes(x, fs, f0, f1, rate) for c, x in chans.items()}
    swapped = [] if silent else swap_problem(amp, kind, path, drop)
    _report(swapped, flags, on_data_problem)  # before the band: a swapped pair is not a wrong band
    drive = chans[RESPONSE if swapped else ref]
    if ref in silent:  # no drive to measure: the flag says why, not a misleading band error
        f_first = f_last = tol = float("nan")
    else:
        f_first, f_last, tol = _drive_band(drive, fs, f0, f1, rate)
    for label, got, exp in (("start", f_first, f0), ("end", f_last, f1)):
        if abs(got - exp) > tol:
            _check_head(drive, amp[RESPONSE if swapped else ref], fs, f0, f1, rate, path, run, band)
            fail(path, f"the drive frequency at the sweep {label} is {got:.0f} Hz, not {exp:g} Hz "
                 f"(+/- {tol:.0f} Hz) as the manifest band {band} says",
                 f"correct direction, f_start_hz, f_stop_hz or sweep_rate_hz_per_s of run {run}"
                 + (f" (the record's data problems first: {', '.join(flags)})" if flags else ""))
    if not silent and not swapped:
        _report(level_problems(chans, amp, kind, row, fs, path, run, drop, df.attrs.get("sources", {})), flags,
                on_data_problem)
    rms = {f"rms_{c}": float("nan") for c in (*REFERENCE.values(), RESPONSE)}
    rms.update({f"rms_{c}": float(np.sqrt(np.mean(x[np.isfinite(x)] ** 2))) for c, x in chans.items()
                if np.isfinite(x).any()})
    return {"n_samples": t.size, "duration_s": t.size / fs, "fs_measured_hz": fs, "excitation": kind, **rms,
            "f_first_hz": f_first, "f_last_hz": f_last, "f_tolerance_hz": tol, "flags": flags}


def _check_head(drive: NDArray[np.float64], amp: NDArray[np.float64], fs: float, f0: float, f1: float, rate: float,
                path: object, run: str, band: str) -> None:
    """Fail naming a silent pre-trigger head when the record, from the drive's onset on, fits the manifest band.

    The head ends where the drive (median removed) first exceeds ``HEAD_LEVEL`` of its
    median window amplitude `amp`; the onset is the first sample above six times the
    head's noise (robust RMS of its first half), which finds the start of a ramp too.
    """
    if amp.size == 0 or not np.median(amp) > 0:
        return
    x = np.nan_to_num(np.abs(drive - np.nanmedian(drive)))
    i_head = int(np.argmax(x > HEAD_LEVEL * float(np.median(amp))))
    if i_head < 2:
        return
    noise = 1.4826 * float(np.median(x[: i_head // 2 + 1]))
    i_on = int(np.argmax(x[: i_head + 1] > 6.0 * noise)) if noise > 0 else i_head
    if i_on == 0 or drive.size - i_on < 0.95 * abs(f1 - f0) / rate * fs:
        return
    first, last, tol = _drive_band(drive[i_on:], fs, f0, f1, rate)
    if abs(first - f0) <= tol and abs(last - f1) <= tol:
        fail(path, f"the drive starts {i_on / fs:.4g} s after the record's first sample (a silent pre-trigger head "
             f"of {i_on} samples), so the record does not start with the sweep {band}",
             f"trim the head so that the record starts with the sweep, or give the sweep's start in the manifest's "
             f"sweep_start_s column ({i_on / fs:.4g} for run {run})")


def _check_time(t: NDArray[np.float64], fs: float, path: object, run: str) -> float:
    """Check the time axis (s) against the manifest's sample rate `fs` (Hz); return the measured rate (Hz)."""
    if t.size < 16:
        fail(path, f"it has only {t.size} samples", "export the whole record")
    if not np.isfinite(t).all():
        fail(path, f"time_s has {np.count_nonzero(~np.isfinite(t))} NaN/inf values", "export a complete time column")
    dt = np.diff(t)
    if (dt <= 0).any():
        i = int(np.flatnonzero(dt <= 0)[0])
        fail(path, f"time_s does not increase from sample {i} to {i + 1} ({t[i]:.9g} s then {t[i + 1]:.9g} s)",
             "export the samples in time order without repeats")
    step = np.median(dt)
    jumps = np.flatnonzero(abs(dt / step - 1) > 0.25)
    if jumps.size:
        i = int(jumps[0])
        fail(path, f"time_s jumps by {dt[i]:.3g} s after {t[i]:.9g} s (the usual step is {step:.3g} s)",
             "export an evenly sampled record without gaps")
    fs_meas = (t.size - 1) / (t[-1] - t[0])
    units = {**TIME_UNITS, "sample numbers": 1.0 / fs}  # a time column in another unit, guessed and named
    for unit, seconds in units.items():
        if abs(fs_meas / fs - 1) > FS_RTOL and abs(fs_meas / (seconds * fs) - 1) <= 0.01:
            fail(path, f"time_s advances by {step:.6g} per sample, which at sample_rate_hz = {fs:g} Hz means it is "
                 f"written in {unit}", f"export time_s in seconds (multiply by {seconds:.6g})")
    if abs(fs_meas / fs - 1) > FS_RTOL:
        fail(path, f"the measured sample rate {fs_meas:.6g} Hz differs from sample_rate_hz = {fs:g} Hz "
             f"by {abs(fs_meas / fs - 1):.2%}", f"correct sample_rate_hz for run {run} in manifest.csv")
    i = np.arange(t.size, dtype=np.float64)
    off = t - np.polyval(np.polyfit(i, t, 1), i)  # s, off the best uniform grid
    excess = np.abs(off) - time_resolution(t) - JITTER * step
    if (excess > 0).any():
        k = int(np.argmax(np.abs(off)))
        fail(path, f"time_s is not evenly spaced: sample {k} sits {abs(off[k]) / step:.1%} of a step off a uniform "
             f"grid (at {t[k]:.9g} s; {np.count_nonzero(excess > 0)} samples beyond {JITTER:.0%}), more than the "
             "times' rounding explains", "export the DAQ's own sample times (t0 + i / sample rate) or a record "
             "resampled to a uniform grid")
    return float(fs_meas)


def time_resolution(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """How far each time may sit off its true value from the way the times were written (s).

    Parameters
    ----------
    t : ndarray of float, shape (n,)
        Sample times (s).

    Returns
    -------
    ndarray of float, shape (n,)
        Half the rounding step of each time, under every way of writing that the values
        fit exactly: a fixed number of decimals (``%.6f``: 5e-7 s), a number of
        significant digits (``%.7g``: 5e-7 s at 1-10 s, 5e-6 s at 10-100 s) or single
        precision (float32: 6e-8 of the time); 0 for times at full double precision.
        A text export's rounding is not jitter.
    """
    sample = np.concatenate([t[:2000], t[t.size // 2: t.size // 2 + 2000], t[-2000:]])  # runs of neighbours
    bound = np.zeros_like(t)
    if np.array_equal(sample.astype(np.float32).astype(np.float64), sample):
        bound = np.maximum(bound, 2.0**-24 * np.abs(t))
    for k in range(0, 10):  # fixed decimals
        x = sample * 10.0**k
        if np.all(np.abs(x - np.rint(x)) <= 1e-6 + 1e-12 * np.abs(x)):
            bound = np.maximum(bound, 0.5 * 10.0**-k)
            break
    nz, tz = sample[sample != 0], np.where(t != 0, np.abs(t), 1.0)
    for d in range(1, 15):  # significant digits
        q = 10.0 ** (np.floor(np.log10(np.abs(nz))) - d + 1)
        if nz.size and np.all(np.abs(nz / q - np.rint(nz / q)) <= 1e-6):
            bound = np.maximum(bound, 0.5 * 10.0 ** (np.floor(np.log10(tz)) - d + 1))
            break
    return bound


def _data_problems(t: NDArray[np.float64], chans: dict[str, NDArray[np.float64]], clip_run: int,
                   path: object, run: str) -> list[tuple[str, str]]:
    """(flag, one-sentence message) for each NaN/inf or clipped channel."""
    drop = f"or remove run {run} from manifest.csv"
    out = []
    for name, x in chans.items():
        bad = ~np.isfinite(x)
        if bad.any():
            out.append((f"nonfinite:{name}",
                        f"{path}: column '{name}' has {_count(np.count_nonzero(bad), 'NaN/inf value')} (first at "
                        f"{t[np.argmax(bad)]:.6g} s); re-export the record without missing values {drop}."))
        finite = x[~bad]
        if finite.size and finite.min() == finite.max():
            out.append((f"constant:{name}",
                        f"{path}: column '{name}' is constant at {finite[0]:.6g} (no signal recorded); check the "
                        f"sensor, its cable and the channel's assignment and repeat the run {drop}."))
            continue
        levels = clip_levels(x, clip_run)
        if levels:
            where = " and ".join(f"{_count(n, 'sample')} at {v:.6g}" for v, n, _ in levels)
            first = min(i for _, _, i in levels)
            out.append((f"clipped:{name}",
                        f"{path}: column '{name}' is clipped ({where}, its full scale, first at {t[first]:.6g} s); "
                        f"repeat the run with a wider input range or a lower level {drop}."))
    return out


def _report(problems: list[tuple[str, str]], flags: list[str], on_data_problem: OnDataProblem) -> None:
    """Raise the first data problem (``'error'``) or warn and append every flag (``'flag'``)."""
    for flag, msg in problems:
        if on_data_problem == "error":
            raise CampaignError(msg)
        warnings.warn(msg, CampaignWarning, stacklevel=3)
        flags.append(flag)


def _drive_band(ref: NDArray[np.float64], fs: float, f0: float, f1: float,
                rate: float) -> tuple[float, float, float]:
    """Drive frequency (Hz) at the sweep's start and expected end, and the tolerance (Hz).

    `ref` is the reference channel sampled at `fs` (Hz) from the sweep's start; the sweep
    runs linearly from `f0` to `f1` (Hz) at `rate` (Hz/s). Each window's peak frequency
    is the frequency at the window's centre, referred to the sweep's start or end with
    `rate`.
    """
    sign = 1.0 if f1 > f0 else -1.0
    sweep_s = abs(f1 - f0) / rate
    win = min(max(MIN_CYCLES / min(f0, f1), np.sqrt(2.0 / rate)), sweep_s / 4)
    nw = max(int(round(win * fs)), 8)
    tol = rate * (nw / fs) / 2 + fs / nw  # half the sweep within a window + one FFT bin
    i_end = min(ref.size, int(round(sweep_s * fs)))
    centre_first = (nw - 1) / 2 / fs  # s after the sweep's start
    centre_last = (2 * i_end - nw - 1) / 2 / fs
    f_first = peak_frequency(ref[:nw], fs) - sign * rate * centre_first
    f_last = peak_frequency(ref[i_end - nw:i_end], fs) + sign * rate * (sweep_s - centre_last)
    return f_first, f_last, tol
