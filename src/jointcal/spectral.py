"""Spectral helpers below `jointcal.io` and `jointcal.measure`: a peak's vertex, a record's peak frequency.

Both the raw-data checks (`jointcal.io`: the drive's band) and the read-outs
(`jointcal.measure`: envelopes, test kinds) use them, so they live beside `jointcal.units`
and import nothing of the package: a workflow stage's code hash (`jointcal._workflow.stage_hash`)
then follows what the stage runs, and an edit of `jointcal.measure.peaks` leaves ingest alone.

* `parabola_vertex`: the vertex of the parabola through three samples around a peak
  (a spectral peak on the log magnitude, an envelope's peak on its magnitude).
* `peak_frequency`: the frequency of a record's largest spectral peak, zero-padded and refined
  by `parabola_vertex` on the log magnitude.
* `plateau_end` and `drive_end`: where a dwell's steady state ends, from the response's envelope or
  from the drive (the raw-data checks of a dwell's frequency; the ring-down's start).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["parabola_vertex", "peak_frequency", "plateau_end", "drive_end", "DRIVE_OFF", "HOLD"]

DRIVE_OFF = 0.02  # a drive below this share of its largest value is off
HOLD = 0.05  # a steady state's envelope lies within this share of its plateau


def parabola_vertex(a: ArrayLike, b: ArrayLike, c: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Offset and height of the vertex of the parabola through (-1, a), (0, b), (1, c).

    Parameters
    ----------
    a, b, c : array_like, one shape
        Three equally spaced samples around a peak (b the middle one).

    Returns
    -------
    delta : ndarray
        The vertex's offset from the middle sample, in sample spacings; 0 where the three
        samples do not curve downwards (no peak).
    height : ndarray
        The parabola's value at the vertex, ``b - (a - c) delta / 4``.
    """
    a, b, c = (np.asarray(v, dtype=np.float64) for v in (a, b, c))
    den = a - 2 * b + c
    delta = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, -1.0), 0.0)
    return delta, b - 0.25 * (a - c) * delta


def peak_frequency(x: ArrayLike, fs: float, *, pad: int = 16, window: bool = True,
                   lo: float | None = None) -> float:
    """Frequency of the largest spectral peak of a short record (Hz).

    Parameters
    ----------
    x : array_like of float, shape (n,)
        Short record (any unit); non-finite samples are treated as 0.
    fs : float
        Sample rate (Hz).
    pad : int, optional
        Zero-padding factor of the FFT (the peak is then refined by `parabola_vertex`
        through the three highest lines of the log magnitude).
    window : bool, optional
        Multiply the mean-removed record by a Hann window; False for a free decay, which
        tapers itself.
    lo : float, optional
        Lines up to the first at or above `lo` (Hz) are left out. Default: one line of the
        unpadded record, ``fs / n`` (DC and its leakage: the record is mean-removed).

    Returns
    -------
    float
        Peak frequency (Hz) of the mean-removed (and windowed) record. For a linear chirp
        under the window this is the instantaneous frequency at the record's centre.
    """
    y = np.nan_to_num(np.asarray(x, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    y = y - y.mean()
    if window:
        y = y * np.hanning(y.size)
    nfft = pad * y.size
    mag = np.abs(np.fft.rfft(y, nfft))
    mag[: (pad if lo is None else int(np.ceil(lo * nfft / fs))) + 1] = 0.0
    k = int(np.argmax(mag))
    if 0 < k < mag.size - 1:  # all lines 0: k = 0; a flat top: no curvature, no offset
        k = k + float(parabola_vertex(*np.log(mag[k - 1 : k + 2] + 1e-300))[0])  # on the log magnitude
    return float(k * fs / nfft)


def plateau_end(fs: float, response: ArrayLike) -> tuple[NDArray[np.float64], float, int]:
    """Where a response's steady state (a dwell's) ends.

    Parameters
    ----------
    fs : float
        Sample rate, Hz.
    response : array_like of float, shape (n,)
        The response (any unit; band-passed around the mode where other modes ring).

    Returns
    -------
    env : ndarray, shape (n,)
        Its envelope, |analytic signal| smoothed over 50 ms.
    plateau : float
        The steady level: the median of the envelope where it exceeds half its largest value, the record's
        first and last second (the transform's and a filter's own edges) left out.
    end : int
        The last sample at which the envelope lies within `HOLD` of the plateau: the end of a dwell's steady
        state, or just after an impact's peak.
    """
    from scipy.signal import hilbert

    env = np.abs(hilbert(np.nan_to_num(np.asarray(response, float))))
    env = np.convolve(env, np.ones(max(1, int(0.05 * fs))) / max(1, int(0.05 * fs)), "same")
    edge = min(int(fs), env.size // 8)
    core = env[edge:env.size - edge]
    plateau = float(np.median(core[core >= 0.5 * core.max()]))  # its start may overshoot
    return env, plateau, edge + int(np.flatnonzero(core >= (1 - HOLD) * plateau)[-1])


def drive_end(fs: float, drive: ArrayLike, response: ArrayLike) -> int | None:
    """One sample after a dwell's drive is cut off; None for a drive that is zero throughout.

    The drive is off after the last sample at which |drive| exceeds `DRIVE_OFF` of its largest value, unless
    the response has by then decayed below half its plateau (`plateau_end`). A reference that stays live after
    the cut does that: a force gauge on a shaker left attached reads the armature's reaction, which decays with
    the structure (and at first exceeds the dwell's force); it falls quiet only after the response has, and
    there the end of the response's plateau stands.

    Parameters
    ----------
    fs : float
        Sample rate, Hz.
    drive, response : array_like of float, shape (n,)
        The reference (mean-removed, any unit) and the response (any unit).
    """
    d = np.abs(np.nan_to_num(np.asarray(drive, float)))
    on = np.flatnonzero(d > DRIVE_OFF * d.max()) if d.size and d.max() > 0 else np.empty(0, int)
    if on.size == 0:
        return None
    end = int(on[-1]) + 1
    env, plateau, held = plateau_end(fs, response)
    return held if env[min(end - 1, env.size - 1)] < 0.5 * plateau else end
