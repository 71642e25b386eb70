"""Checks of one run record against its manifest row (`validate_run`, re-exported by `jointcal.io`).

Also the signal helpers it uses: clipping runs and the drive frequency of a short window.
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from jointcal._contract import (
    FS_RTOL, LEVEL, MIN_CYCLES, REFERENCE, RESPONSE, TIME, CampaignError, CampaignWarning,
    OnDataProblem, excitation_of, fail,
)

__all__ = ["validate_run", "clipped_mask"]


def stuck_runs(x: NDArray[np.float64], min_len: int) -> tuple[float, NDArray[np.int64]]:
    """Find runs of samples stuck at the channel's extreme value (clipping).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel (any unit). Non-finite samples never belong to a run.
    min_len : int
        Shortest run, in samples, that counts as clipping (>= 2).

    Returns
    -------
    value : float
        The clipped value of the first run found (same unit as `x`); NaN if none.
    starts : ndarray of int, shape (k,)
        Start index of every run of >= `min_len` consecutive samples equal to the
        channel's maximum or to its minimum; empty when the channel is clean.

    Notes
    -----
    The maximum and the minimum are tested separately, so asymmetric clipping
    (different positive and negative limits) and several clipped segments are found.
    A swept sine sampled at > 2 points per cycle essentially never repeats its
    extreme value exactly on consecutive samples, so exact equality is the test.
    """
    if min_len < 2:
        raise ValueError(f"min_len must be >= 2, got {min_len}")
    finite = np.isfinite(x)
    if not finite.any():
        return float("nan"), np.empty(0, dtype=np.int64)
    found: list[tuple[int, float]] = []
    for value in (np.max(x[finite]), np.min(x[finite])):
        if value == 0.0:  # a silent channel is not clipped
            continue
        at = np.concatenate(([0], (x == value).astype(np.int8), [0]))
        edges = np.diff(at)
        starts = np.flatnonzero(edges == 1)
        stops = np.flatnonzero(edges == -1)
        found += [(int(s), float(value)) for s in starts[stops - starts >= min_len]]
    if not found:
        return float("nan"), np.empty(0, dtype=np.int64)
    found.sort()
    return found[0][1], np.array([s for s, _ in found], dtype=np.int64)


def clipped_mask(x: NDArray[np.float64], min_len: int = 3) -> NDArray[np.bool_]:
    """Samples inside the clipped runs that `stuck_runs` finds (same definition).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel.
    min_len : int
        Shortest run, in samples, that counts as clipping.

    Returns
    -------
    ndarray of bool, shape (n,)
        True for every sample of a run of >= `min_len` consecutive samples equal to the
        channel's maximum or minimum.
    """
    mask = np.zeros(x.shape, dtype=bool)
    finite = np.isfinite(x)
    if not finite.any():
        return mask
    for value in (np.max(x[finite]), np.min(x[finite])):
        if value == 0.0:
            continue
        at = np.concatenate(([0], (x == value).astype(np.int8), [0]))
        edges = np.diff(at)
        for s, e in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            if e - s >= min_len:
                mask[s:e] = True
    return mask


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
        Shortest run of consecutive samples stuck at a channel's maximum or minimum
        that counts as clipping (samples).
    on_data_problem : {'error', 'flag'}, optional
        What to do with data problems (NaN/inf values, clipping): raise, or record
        them in ``flags`` and emit a `CampaignWarning` with the same sentence.
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
        ``f_start_hz``/``f_stop_hz`` (Hz); ``flags``, a list such as
        ``['nonfinite:response_accel_g', 'clipped:base_accel_g']``.

    Raises
    ------
    CampaignError
        Wrong columns or excitation kind, too few samples, non-finite or
        non-increasing or gapped time, sample rate off the manifest by > 0.1 %,
        a record shorter than 95 % of the sweep, a start or end drive frequency off
        the manifest band by more than ``f_tolerance_hz``; with
        ``on_data_problem='error'`` also NaN/inf values and clipping.

    Notes
    -----
    Each window spans ``W = max(20 / f_low, sqrt(2 / rate))`` (at least 20 cycles of
    the lowest frequency; the sqrt balances sweep and resolution), at most a quarter
    of the sweep. The tolerance is ``rate * W / 2 + 1 / W``: the frequency swept
    within half the window plus one FFT bin.
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
    for flag, msg in _data_problems(t, chans, clip_run, path, run):
        if on_data_problem == "error":
            raise CampaignError(msg)
        warnings.warn(msg, CampaignWarning, stacklevel=2)
        flags.append(flag)

    f_first, f_last, tol = _drive_band(chans[REFERENCE[kind]], fs, f0, f1, rate)
    for label, got, exp in (("start", f_first, f0), ("end", f_last, f1)):
        if abs(got - exp) > tol:
            fail(path, f"the drive frequency at the sweep {label} is {got:.0f} Hz, not {exp:g} Hz "
                 f"(+/- {tol:.0f} Hz) as the manifest band {band} says",
                 f"correct direction, f_start_hz, f_stop_hz or sweep_rate_hz_per_s of run {run}")
    rms = {f"rms_{c}": float("nan") for c in (*REFERENCE.values(), RESPONSE)}
    rms.update({f"rms_{c}": float(np.sqrt(np.mean(x[np.isfinite(x)] ** 2))) for c, x in chans.items()})
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
        value, starts = stuck_runs(x, clip_run)
        if starts.size:
            out.append((f"clipped:{name}",
                        f"{path}: column '{name}' is clipped ({_count(starts.size, 'run')} of >= {clip_run} samples "
                        f"stuck at {value:.6g}, first at {t[starts[0]]:.6g} s); repeat the run with a wider input "
                        f"range or a lower level {drop}."))
    return out


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
