"""The time axis of a run record: its checks against the manifest's sample rate, and its rounding.

Private: `jointcal.io._checks.validate_run` calls `check_time`.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import FS_RTOL, fail

__all__ = ["check_time", "time_resolution", "JITTER"]

TIME_UNITS = {"milliseconds": 1e-3, "microseconds": 1e-6, "minutes": 60.0}  # unit -> its size in s
JITTER = 0.02  # samples further than this many steps off a uniform grid (beyond the times' rounding) are jitter


def check_time(t: NDArray[np.float64], fs: float, path: object, run: str) -> float:
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
