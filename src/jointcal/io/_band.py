"""The drive's frequency at a record's start and end, checked against the manifest's band.

Private: `jointcal.io._checks.validate_run` calls `drive_band` and `check_head` (a sweep), `dwell_band` (a dwell).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import MIN_CYCLES, fail
from jointcal.spectral import DRIVE_OFF, drive_end, peak_frequency

__all__ = ["drive_band", "check_head", "dwell_band"]

HEAD_LEVEL = 0.1  # a head quieter than this fraction of the reference's amplitude is silent


def check_head(drive: NDArray[np.float64], amp: NDArray[np.float64], fs: float, f0: float, f1: float, rate: float,
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
    first, last, tol = drive_band(drive[i_on:], fs, f0, f1, rate)
    if abs(first - f0) <= tol and abs(last - f1) <= tol:
        fail(path, f"the drive starts {i_on / fs:.4g} s after the record's first sample (a silent pre-trigger head "
             f"of {i_on} samples), so the record does not start with the sweep {band}",
             f"trim the head so that the record starts with the sweep, or give the sweep's start in the manifest's "
             f"sweep_start_s column ({i_on / fs:.4g} for run {run})")


def drive_band(ref: NDArray[np.float64], fs: float, f0: float, f1: float,
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


TINY = 1e-9  # a dwell is checked as a sweep over this relative band: the sweep's windows, one frequency


def dwell_band(drive: NDArray[np.float64], fs: float, f_d: float, path: object,
               run: str, response: NDArray[np.float64] | None = None) -> tuple[float, float, float, float]:
    """A dwell's drive checked against ``dwell_hz``, and the equivalent sweep its amplitude checks use.

    Parameters
    ----------
    drive : ndarray of float, shape (n,)
        The reference channel (any unit); after the dwell it may be cut to zero (a ring-down follows).
    fs, f_d : float
        Sample rate and the manifest's ``dwell_hz`` (Hz).
    path, run : object, str
        Named in messages.
    response : ndarray of float, shape (n,), optional
        The response: where the drive stays live after the cut (a force gauge on a shaker left
        attached), the dwell ends where the response's steady state does (`jointcal.spectral.drive_end`).

    Returns
    -------
    f0, f1, rate : float
        A linear sweep from `f_d` over ``TINY`` of it that lasts as long as the drive (Hz, Hz, Hz/s):
        the sweep checks' windows of ``MIN_CYCLES`` drive cycles, over the dwell only.
    f_meas : float
        The drive's frequency over the second half of the dwell (Hz).

    Raises
    ------
    CampaignError
        A drive shorter than ``2 MIN_CYCLES`` cycles, or its frequency off `f_d` by more than one
        FFT bin of the half plus 0.1 %.
    """
    x = np.nan_to_num(np.asarray(drive, float) - np.nanmedian(drive))
    if response is None:
        on = np.flatnonzero(np.abs(x) > DRIVE_OFF * np.max(np.abs(x))) if x.size else np.empty(0, int)
        end = int(on[-1]) + 1 if on.size else x.size
    else:
        end = drive_end(fs, x, np.nan_to_num(np.asarray(response, float))) or x.size
    if end / fs * f_d < 2 * MIN_CYCLES:
        fail(path, f"the drive of dwell run {run} lasts {end / fs:.3g} s, fewer than {2 * MIN_CYCLES} cycles at "
             f"dwell_hz = {f_d:g} Hz", f"record a longer dwell or correct dwell_hz of run {run}")
    half = x[end // 2:end]
    got = peak_frequency(half, fs)
    tol = fs / half.size + 1e-3 * f_d
    if abs(got - f_d) > tol:
        fail(path, f"the drive's frequency over the dwell is {got:.4g} Hz, not dwell_hz = {f_d:g} Hz "
             f"(+/- {tol:.2g} Hz) for run {run}", f"correct dwell_hz of run {run} in manifest.csv")
    return f_d, f_d * (1 + TINY), f_d * TINY / (end / fs), got
