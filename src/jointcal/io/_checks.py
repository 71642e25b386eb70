"""Checks of one run record against its manifest row (`validate_run`, re-exported by `jointcal.io`).

The time axis is checked by `jointcal.io._time`, the drive's band by `jointcal.io._band`,
the amplitudes by `jointcal.io._amplitudes` and clipping found by `jointcal.io._clipping`.
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from jointcal.io._amplitudes import level_problems, swap_problem, window_amplitudes
from jointcal.io._band import check_head
from jointcal.io._clipping import clip_levels, clipped_mask
from jointcal.io._dead import dead_problem
from jointcal.io.contract import (
    LEVEL, REFERENCE, RESPONSE, TIME, CampaignError, CampaignWarning, OnDataProblem,
    excitation_kind, excitation_of, fail,
)
from jointcal.io.testkinds import run_test_kind
from jointcal.io._time import check_time, time_resolution

__all__ = ["validate_run", "clipped_mask", "clip_levels", "window_amplitudes", "time_resolution", "UNUSABLE_FLAGS"]

# ingest flags whose run must not enter a calibration: its amplitudes or channels are wrong, its response does
# not respond to the drive (dead), or it is clipped (a linear SDOF clipped at 95-60 % of its resonance peak gives
# damping 14-138 % high even with the frames touching clipped samples left out: the peak itself is missing)
UNUSABLE_FLAGS = ("level", "units", "swapped", "constant", "clipped", "dead")


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
        response in other units than declared, a response that does not respond to the
        drive): raise, or
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
        signal); ``response_units_check``, what the base-driven response-units check
        found, in words: '<unit> confirmed: ...', 'flagged: ...', 'undecided: <why>' or
        'not checkable: ...' (force- and voltage-driven); ``flags``, a list such as ``['nonfinite:response_accel_g',
        'clipped:base_accel_g']``; the words are ``nonfinite``, ``constant``,
        ``clipped``, ``swapped``, ``level``, ``units`` and ``dead`` (a response that
        does not follow the drive, `jointcal.io._dead`) (see `UNUSABLE_FLAGS`).

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
    a base-driven response's units) are `jointcal.io._amplitudes`'; swapped columns are
    looked for before the band, whose drive is then the response column.

    Time samples more than ``JITTER`` (2 %) of a step off the best uniform grid,
    beyond the rounding of the way the times were written, are jitter.
    """
    if on_data_problem not in ("error", "flag"):
        raise ValueError(f"on_data_problem must be 'error' or 'flag', got {on_data_problem!r}")
    run = repr(row["run_id"])
    kind = excitation_of([str(c) for c in df.columns], path)
    want = excitation_kind([c for c in LEVEL.values() if c in row])
    if kind != want:
        fail(path, f"it holds {REFERENCE[kind]} but the manifest gives {LEVEL[want]} for run {run}",
             f"export {REFERENCE[want]} or correct the manifest's level column")
    t = df[TIME].to_numpy(np.float64)
    ref = REFERENCE[kind]
    chans = {c: df[c].to_numpy(np.float64) for c in (ref, RESPONSE)}
    fs = check_time(t, float(row["sample_rate_hz"]), path, run)
    test = run_test_kind(row)
    if test.band is None:  # no drive over a band (`jointcal.io.testkinds`)
        return _channel_checks(t, chans, fs, kind, clip_run, path, run, on_data_problem, test.unchecked)
    f0, f1, rate, f_meas = test.band(row, chans[ref], chans[RESPONSE], fs, path, run)
    row = {**row, "f_start_hz": f0, "f_stop_hz": f1, "sweep_rate_hz_per_s": rate}  # a dwell: a sweep of one frequency
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
        f_first, f_last, tol = test.drive_ends(drive, fs, f0, f1, rate, f_meas, t.size)
    for label, got, exp in (("start", f_first, f0), ("end", f_last, f1)):
        if abs(got - exp) > tol:
            check_head(drive, amp[RESPONSE if swapped else ref], fs, f0, f1, rate, path, run, band)
            fail(path, f"the drive frequency at the sweep {label} is {got:.0f} Hz, not {exp:g} Hz "
                 f"(+/- {tol:.0f} Hz) as the manifest band {band} says",
                 f"correct direction, f_start_hz, f_stop_hz or sweep_rate_hz_per_s of run {run}"
                 + (f" (the record's data problems first: {', '.join(flags)})" if flags else ""))
    if not silent and not swapped:
        _report(dead_problem(chans[ref], chans[RESPONSE], fs, f0, f1, rate, path, drop,
                             df.attrs.get("sources", {}).get(RESPONSE, {})), flags, on_data_problem)
    units_note = "undecided: the channels are silent or swapped"
    if not silent and not swapped and not any(f.startswith("dead:") for f in flags):
        problems, units_note = level_problems(chans, amp, kind, row, fs, path, run, drop, df.attrs.get("sources", {}))
        _report(problems, flags, on_data_problem)
    elif any(f.startswith("dead:") for f in flags):
        units_note = "undecided: the response does not respond to the drive"
    rms = {f"rms_{c}": float("nan") for c in (*REFERENCE.values(), RESPONSE)}
    rms.update({f"rms_{c}": float(np.sqrt(np.mean(x[np.isfinite(x)] ** 2))) for c, x in chans.items()
                if np.isfinite(x).any()})
    return {"n_samples": t.size, "duration_s": t.size / fs, "fs_measured_hz": fs, "excitation": kind, **rms,
            "f_first_hz": f_first, "f_last_hz": f_last, "f_tolerance_hz": tol, "response_units_check": units_note,
            "flags": flags}


def _channel_checks(t: NDArray[np.float64], chans: dict[str, NDArray[np.float64]], fs: float, kind: str,
                    clip_run: int, path: object, run: str, on_data_problem: OnDataProblem,
                    unchecked: str) -> dict[str, Any]:
    """The checks of a kind with no drive over a band (a ring-down): its channels' data problems (a reference cut
    to zero or an impact's short pulse is no problem: only its NaN/inf values count); no band, level or
    drive-following checks (`unchecked` says why, in ``response_units_check``)."""
    flags: list[str] = []
    problems = _data_problems(t, chans, clip_run, path, run)
    _report([p for p in problems if p[0].endswith(RESPONSE) or p[0].startswith("nonfinite")], flags, on_data_problem)
    rms = {f"rms_{c}": float("nan") for c in (*REFERENCE.values(), RESPONSE)}
    rms.update({f"rms_{c}": float(np.sqrt(np.mean(x[np.isfinite(x)] ** 2))) for c, x in chans.items()
                if np.isfinite(x).any()})
    nan = float("nan")
    return {"n_samples": t.size, "duration_s": t.size / fs, "fs_measured_hz": fs, "excitation": kind, **rms,
            "f_first_hz": nan, "f_last_hz": nan, "f_tolerance_hz": nan,
            "response_units_check": unchecked, "flags": flags}


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


