"""Clipping of a recorded channel: the pile-up of samples at an ADC's full scale.

Private: `jointcal.io._checks` flags clipped channels with `clip_levels`; the envelopes
leave out the samples `clipped_mask` marks (re-exported by `jointcal.io._checks`).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["quantum", "clip_levels", "clipped_mask"]


def quantum(v: NDArray[np.float64]) -> float:
    """Quantisation step of a channel near its extremes (unit of `v`).

    The smallest spacing between distinct values among the 4096 largest and the 4096
    smallest finite samples of `v` (shape (n,)) strictly inside its range (a clipped
    extreme holds one value): the ADC's LSB for quantised data. At most 1e-3 of the
    range (a 10-bit ADC), at least 1e-12 of the largest magnitude (float rounding).
    """
    v = v[np.isfinite(v)]
    if v.size < 2:
        return 0.0
    lo, hi = float(v.min()), float(v.max())
    inner = v[(v > lo) & (v < hi)]
    step = 1e-3 * (hi - lo)
    if inner.size >= 2:
        k = min(inner.size, 4096)
        tails = np.unique(np.concatenate((np.partition(inner, inner.size - k)[inner.size - k:],
                                          np.partition(inner, k - 1)[:k], [lo, hi])))
        step = min(step, float(np.diff(tails).min()))
    return max(step, 1e-12 * max(abs(lo), abs(hi)))


def clip_levels(x: NDArray[np.float64], min_count: int = 3) -> list[tuple[float, int, int]]:
    """Find the extreme values at which a channel is clipped, from its amplitude distribution.

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel (any unit). Non-finite samples are ignored.
    min_count : int
        Fewest samples at one extreme that count as clipping (>= 2).

    Returns
    -------
    list of (value, count, first)
        For the maximum and the minimum separately: the clipped value (unit of `x`),
        the number of samples within one quantisation step of it, and the index of
        the first; empty when the channel is clean.

    Notes
    -----
    A clipped channel piles up at its full scale: many samples sit exactly at (or
    within one quantisation step of) the same extreme value, whatever the length of
    each flat top (at 2.2 kHz sampled at 12.8 kHz, a clip at 95 % of the peak lasts
    one sample per half cycle). A noisy swept sine reaches its extreme once, and its
    next-highest samples are spread below it. An extreme counts as clipped when
    `min_count` consecutive samples sit within one step of it (a flat top no sine
    has), or when

    * at least `min_count` samples sit within one step of it,
    * they outnumber three times the samples in the band just below it, of width
      ``max(3 steps, 1e-3 (extreme - median))`` (the histogram's pile-up at the
      extreme: a noiseless synthetic chirp may hit its crest exactly on a few samples,
      but far more of its samples then lie just below), and
    * they outnumber twice the samples at the value nearest the median (a noiseless
      tone at a rational frequency repeats every value, not only its extremes).

    The step is the smallest spacing of the distinct values near the extremes (the
    ADC's LSB for quantised data; float rounding otherwise). A constant channel and
    an extreme of exactly 0 (a silent channel) are not clipping. Clipping at 60-99 %
    of the peak is found in 24- and 16-bit records at 12.8 and 25.6 kHz; a 12-bit
    record may hide a slight clip in its coarse steps.
    """
    if min_count < 2:
        raise ValueError(f"min_count must be >= 2, got {min_count}")
    finite = np.isfinite(x)
    v = x[finite]
    if v.size < 2 or v.max() == v.min():
        return []
    step = quantum(v)
    tol = 1.001 * step
    centre = float(np.median(v))
    found = []
    for sign in (1.0, -1.0):
        y = sign * v  # the maximum of y is the channel's maximum (sign 1) or minimum (sign -1)
        top, c = float(y.max()), sign * centre
        if top == 0.0:
            continue
        at = y >= top - tol
        below = (y >= top - max(3.001 * step, 1e-3 * (top - c))) & ~at
        mid = y[np.argmin(np.abs(y - c))]
        n_at, n_below = int(np.count_nonzero(at)), int(np.count_nonzero(below))
        n_mid = int(np.count_nonzero(np.abs(y - mid) <= tol))
        edges = np.diff(np.concatenate(([0], at.astype(np.int8), [0])))
        longest = int((np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)).max())
        if longest >= min_count or (n_at >= min_count and n_at > 3 * n_below and n_at > 2 * n_mid):
            first = int(np.flatnonzero(finite)[np.argmax(at)])
            found.append((sign * top, n_at, first))
    return found


def clipped_mask(x: NDArray[np.float64], min_count: int = 3) -> NDArray[np.bool_]:
    """Samples at a clipped extreme that `clip_levels` finds (same definition).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel.
    min_count : int
        Fewest samples at one extreme that count as clipping.

    Returns
    -------
    ndarray of bool, shape (n,)
        True for every sample within one quantisation step of a clipped maximum or
        minimum (the samples whose true value is unknown).
    """
    mask = np.zeros(x.shape, dtype=bool)
    levels = clip_levels(x, min_count)
    if not levels:
        return mask
    v = x[np.isfinite(x)]
    step = quantum(v)
    for value, _, _ in levels:
        mask |= np.abs(x - value) <= step * 1.001
    return mask
