"""Windows of a linear sweep, ``MIN_CYCLES`` drive cycles each, and the per-window sums the amplitude checks use.

Private: `jointcal.io._amplitudes`, `jointcal.io._transmissibility` and `jointcal.io._dead`
cut a record into these windows.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import MIN_CYCLES

__all__ = ["windows", "sums", "quadrature"]


def windows(n: int, fs: float, f0: float, f1: float, rate: float) -> tuple[NDArray[np.intp], int]:
    """Window index of each of the first samples of the sweep (``MIN_CYCLES`` drive cycles each), and their count.

    The drive's phase in cycles, ``f0 t + sign rate t^2 / 2``, is cut every ``MIN_CYCLES``
    cycles; only whole windows within the sweep count (the last, partial one is left out).
    `n` samples at `fs` (Hz) of the sweep `f0` -> `f1` (Hz) at `rate` (Hz/s).
    """
    sweep_s = abs(f1 - f0) / rate
    t = np.arange(min(n, int(round(sweep_s * fs)))) / fs
    cycles = f0 * t + 0.5 * np.sign(f1 - f0) * rate * t**2
    k = (cycles // MIN_CYCLES).astype(np.intp)
    whole = int((f0 * sweep_s + 0.5 * np.sign(f1 - f0) * rate * sweep_s**2) // MIN_CYCLES)
    return k, min(whole, int(k[-1]) + 1 if k.size else 0)


def sums(k: NDArray[np.intp], m: int, *values: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Per-window sums of each array (shape (n,), n >= k.size) over the samples with index ``k < m``."""
    use = k < m
    return [np.bincount(k[use], weights=v[: k.size][use], minlength=m)[:m] for v in values]


def quadrature(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The Hilbert transform of `x` (every frequency shifted by -90 degrees), by FFT, shape of `x`."""
    spec = np.fft.rfft(x)
    spec[0] = 0.0
    if x.size % 2 == 0:
        spec[-1] = 0.0
    return np.fft.irfft(-1j * spec, x.size)
