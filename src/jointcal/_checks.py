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

from jointcal._clipping import clip_levels, clipped_mask
from jointcal._contract import (
    FS_RTOL,
    LEVEL,
    MIN_CYCLES,
    REFERENCE,
    RESPONSE,
    TIME,
    CampaignError,
    CampaignWarning,
    OnDataProblem,
    excitation_of,
    fail,
)

__all__ = ["validate_run", "clipped_mask", "clip_levels", "UNUSABLE_FLAGS"]

LEVEL_RTOL = 0.10  # reference amplitude vs the manifest's level: 10x a controller's normal 1 % ripple
UNIT_RTOL = 0.015  # a ratio this close to a unit factor is named as a units mistake (example: within 0.2 %)
SWAP_PEAK = 2.0  # a controlled reference never peaks at twice its median amplitude over the sweep
UNIT_FACTORS = {  # excitation -> {unit a record or level may wrongly be in: its size in the contract's unit}
    "base": {"m/s^2": 9.80665, "in/s^2": 386.089, "ft/s^2": 32.174},
    "force": {"N": 4.44822},
}
TIME_UNITS = {"milliseconds": 1e-3, "microseconds": 1e-6, "minutes": 60.0}  # unit -> its size in s
# ingest flags whose run must not enter a calibration: its amplitudes or channels are wrong, or
# it is clipped (a linear SDOF clipped at 95-60 % of its resonance peak gives damping 14-138 %
# high even with the frames touching clipped samples left out: the peak itself is missing)
UNUSABLE_FLAGS = ("level", "swapped", "constant", "clipped")


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
        The record as returned by `read_run`.
    row : mapping
        Its manifest row (see `read_manifest`).
    path : path-like
        The record's file, named in messages.
    clip_run : int, optional
        Fewest samples at a channel's maximum or minimum (within one quantisation
        step) that count as clipping, flat tops of any length (see `clip_levels`).
    on_data_problem : {'error', 'flag'}, optional
        What to do with data problems (NaN/inf values, a constant channel, clipping,
        swapped channels, a reference amplitude off the manifest's level): raise, or
        record them in ``flags`` and emit a `CampaignWarning` with the same sentence.
        Structural problems always raise.

    Returns
    -------
    dict
        ``n_samples``; ``duration_s`` (n / fs, s); ``fs_measured_hz`` (Hz);
        ``excitation`` ('base' or 'force'); ``rms_base_accel_g`` (g),
        ``rms_force_lbf`` (lbf), ``rms_response_accel_g`` (g) (NaN for the absent
        reference); ``f_first_hz`` and ``f_last_hz``, the drive frequency measured in
        a short window at the record's start and at the sweep's expected end time
        (which a free-decay tail may follow), each referred to that instant with the
        manifest's sweep rate (Hz); ``f_tolerance_hz``, the allowed deviation from
        ``f_start_hz``/``f_stop_hz`` (Hz) (the three NaN when the reference holds no
        signal); ``flags``, a list such as ``['nonfinite:response_accel_g',
        'clipped:base_accel_g']``; the words are ``nonfinite``, ``constant``,
        ``clipped``, ``swapped`` and ``level`` (see `UNUSABLE_FLAGS`).

    Raises
    ------
    CampaignError
        Wrong columns or excitation kind, too few samples, non-finite or
        non-increasing or gapped time, sample rate off the manifest by > 0.1 %,
        a record shorter than 95 % of the sweep, a start or end drive frequency off
        the manifest band by more than ``f_tolerance_hz``; with
        ``on_data_problem='error'`` also the data problems.

    Notes
    -----
    Each window spans ``W = max(20 / f_low, sqrt(2 / rate))`` (at least 20 cycles of
    the lowest frequency; the sqrt balances sweep and resolution), at most a quarter
    of the sweep. The tolerance is ``rate * W / 2 + 1 / W``: the frequency swept
    within half the window plus one FFT bin.

    The reference's median amplitude over 20-cycle windows of the sweep must be the
    manifest's level within ``LEVEL_RTOL`` (10 %: ten times a controller's normal
    ripple; the example campaign is within 0.2 %); a ratio within ``UNIT_RTOL``
    (1.5 %) of a unit factor (9.80665 for m/s^2, 386.089 for in/s^2, 4.44822 for N)
    is named as a units mistake, any other as a wrong level or sensitivity. A
    reference peaking at more than ``SWAP_PEAK`` times its median while the response
    stays flatter than half that is taken for swapped columns.
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
    chans = {c: df[c].to_numpy(np.float64) for c in (REFERENCE[kind], RESPONSE)}
    f0, f1, rate = float(row["f_start_hz"]), float(row["f_stop_hz"]), float(row["sweep_rate_hz_per_s"])
    fs = _check_time(t, float(row["sample_rate_hz"]), path, run)
    sweep_s = abs(f1 - f0) / rate
    band = f"{f0:g} -> {f1:g} Hz at {rate:g} Hz/s"
    if t.size / fs < 0.95 * sweep_s:
        fail(path, f"the record lasts {t.size / fs:.4g} s but the manifest band {band} needs {sweep_s:.4g} s",
             f"check f_start_hz, f_stop_hz and sweep_rate_hz_per_s of run {run} or export the whole record")

    flags: list[str] = []
    problems = _data_problems(t, chans, clip_run, path, run)
    _report(problems, flags, on_data_problem)
    ref = REFERENCE[kind]
    silent = {f.split(":", 1)[1] for f in flags if f.split(":", 1)[0] == "constant"}
    silent |= {c for c, x in chans.items() if not np.isfinite(x).any()}
    if ref in silent:  # no drive to measure: the flag says why, not a misleading band error
        f_first = f_last = tol = float("nan")
    else:
        f_first, f_last, tol = _drive_band(chans[ref], fs, f0, f1, rate)
    for label, got, exp in (("start", f_first, f0), ("end", f_last, f1)):
        if abs(got - exp) > tol:
            fail(path, f"the drive frequency at the sweep {label} is {got:.0f} Hz, not {exp:g} Hz "
                 f"(+/- {tol:.0f} Hz) as the manifest band {band} says",
                 f"correct direction, f_start_hz, f_stop_hz or sweep_rate_hz_per_s of run {run}"
                 + (f" (the record's data problems first: {', '.join(flags)})" if flags else ""))
    if not silent:
        _report(_amplitude_problems(chans, kind, row, fs, sweep_s, path, run), flags, on_data_problem)
    rms = {f"rms_{c}": float("nan") for c in (*REFERENCE.values(), RESPONSE)}
    rms.update({f"rms_{c}": float(np.sqrt(np.mean(x[np.isfinite(x)] ** 2))) for c, x in chans.items()
                if np.isfinite(x).any()})
    return {"n_samples": t.size, "duration_s": t.size / fs, "fs_measured_hz": fs, "excitation": kind, **rms,
            "f_first_hz": f_first, "f_last_hz": f_last, "f_tolerance_hz": tol, "flags": flags}


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
    return float(fs_meas)


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


def window_amplitudes(x: NDArray[np.float64], fs: float, sweep_s: float, f_low: float) -> NDArray[np.float64]:
    """Amplitude of a channel in consecutive windows over the sweep (unit of `x`).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel, sampled at `fs` (Hz) from the sweep's start.
    fs : float
        Sample rate (Hz).
    sweep_s : float
        Duration of the sweep (s); a free-decay tail after it is left out.
    f_low : float
        Lowest drive frequency (Hz): each window spans ``MIN_CYCLES`` of its cycles.

    Returns
    -------
    ndarray of float, shape (k,)
        ``sqrt(2) * RMS`` of each mean-removed window (the amplitude of a sine), for
        the windows with more than half their samples finite.
    """
    n = max(int(round(MIN_CYCLES / f_low * fs)), 8)
    m = min(x.size, int(round(sweep_s * fs))) // n
    w = x[: m * n].reshape(m, n)
    ok = np.isfinite(w)
    keep = ok.mean(axis=1) > 0.5
    w, ok = w[keep], ok[keep]
    mean = np.where(ok, w, 0.0).sum(axis=1, keepdims=True) / ok.sum(axis=1, keepdims=True)
    return np.sqrt(2.0 * np.where(ok, (w - mean) ** 2, 0.0).sum(axis=1) / ok.sum(axis=1))


def _amplitude_problems(chans: dict[str, NDArray[np.float64]], kind: str, row: Mapping[str, Any], fs: float,
                        sweep_s: float, path: object, run: str) -> list[tuple[str, str]]:
    """(flag, one-sentence message) for swapped channels or a reference amplitude off the manifest's level.

    Only for a controlled reference (base acceleration or force): the controller holds
    its amplitude at the level within a ripple, so the median window amplitude is the
    level and the largest is barely above it, while the response peaks at resonance.
    """
    if kind not in UNIT_FACTORS or LEVEL[kind] not in row:
        return []
    ref = REFERENCE[kind]
    drop = f"or remove run {run} from manifest.csv"
    f_low = min(float(row["f_start_hz"]), float(row["f_stop_hz"]))
    amp = {c: window_amplitudes(x, fs, sweep_s, f_low) for c, x in chans.items()}
    if min(a.size for a in amp.values()) < 3:
        return []
    flat = {c: float(a.max() / np.median(a)) if np.median(a) > 0 else np.inf for c, a in amp.items()}
    if flat[ref] > SWAP_PEAK and flat[RESPONSE] < flat[ref] / 2:
        return [(f"swapped:{ref}",
                 f"{path}: column '{ref}' peaks at {flat[ref]:.3g} times its median amplitude while "
                 f"'{RESPONSE}' stays within {flat[RESPONSE]:.2f} times (the controlled reference is flat, the "
                 f"response peaks at resonance), so the two columns look swapped; export each channel under "
                 f"its own name {drop}.")]
    level, unit = float(row[LEVEL[kind]]), LEVEL[kind].split("_", 1)[1]
    got = float(np.median(amp[ref]))
    ratio = got / level
    # a base acceleration is controlled to its level; a force often is not (an open-loop
    # shaker's force drops out at the structure's resonance), so for a force only a
    # units mistake or a factor of two counts
    rtol = LEVEL_RTOL if kind == "base" else 1.0
    if abs(ratio - 1) <= LEVEL_RTOL or (abs(np.log(ratio)) <= np.log(1 + rtol) and not any(
            abs(ratio / f - 1) <= UNIT_RTOL or abs(ratio * f - 1) <= UNIT_RTOL for f in UNIT_FACTORS[kind].values())):
        return []
    what = "base" if kind == "base" else kind
    said = (f"{what} amplitude is {got:.3g} {unit} where the manifest says {LEVEL[kind]} = {level:g} {unit} "
            f"for run {run}")
    for other, factor in UNIT_FACTORS[kind].items():
        if abs(ratio / factor - 1) <= UNIT_RTOL:
            chans_in = f"{ref} and {RESPONSE}" if kind == "base" else ref  # both accelerations share the unit
            return [(f"level:{ref}", f"{path}: {said} (x{ratio:.4g}): is the record in {other}?; export "
                     f"{chans_in} in {unit} (divide by {factor:g}) {drop}.")]
        if abs(ratio * factor - 1) <= UNIT_RTOL:
            return [(f"level:{ref}", f"{path}: {said} (x1/{1 / ratio:.4g}): is {LEVEL[kind]} written in {other}?; "
                     f"write {LEVEL[kind]} of run {run} in {unit} in manifest.csv {drop}.")]
    return [(f"level:{ref}", f"{path}: {said} (x{ratio:.3g}, more than {rtol:.0%} off): the manifest's level "
             f"or the channel's sensitivity is wrong; correct {LEVEL[kind]} of run {run} in manifest.csv or the "
             f"channel's calibration {drop}.")]


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
