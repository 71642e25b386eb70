"""Spectral helpers below `jointcal.io` and `jointcal.measure`: a peak's vertex, a record's peak frequency.

Both the raw-data checks (`jointcal.io`: the drive's band) and the read-outs
(`jointcal.measure`: envelopes, test kinds) use them, so they live beside `jointcal.units`
and import nothing of the package: a workflow stage's code hash (`jointcal._workflow.stage_hash`)
then follows what the stage runs, and an edit of `jointcal.measure.peaks` leaves ingest alone.

* `parabola_vertex`: the vertex of the parabola through three samples around a peak
  (a spectral peak on the log magnitude, an envelope's peak on its magnitude).
* `peak_frequency`: the frequency of a record's largest spectral peak, zero-padded and refined
  by `parabola_vertex` on the log magnitude.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["parabola_vertex", "peak_frequency"]


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
