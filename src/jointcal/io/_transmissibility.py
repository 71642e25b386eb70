"""A base-driven run's response/base ratio below resonance: the response's own scale, or why the record cannot say.

Private: `jointcal.io._amplitudes.level_problems` reads the response's units from
`response_ratio`; `low_frequency_ratio` is its older tuple form.

A base-driven structure follows its base well below resonance: a single mode gives
``|H| = 1 / (1 - (f / f_peak)^2)`` there, so ``|H| (1 - (f / f_peak)^2)`` is 1 when both
channels are in one unit, and 9.81 when the response is in m/s^2 under the g name. It
needs a band that starts below resonance, with one mode's rise over its bottom; the
resonance may lie within the band or above its top (then ``f_peak`` is bounded below by
the band's top, and the scale by the two ends of that bound).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from jointcal.io._windows import quadrature, sums, windows

__all__ = ["LowRatio", "response_ratio", "low_frequency_ratio"]

LOW_RATIO_MAX = 0.8  # the band must start below 0.8 x the resonance
BEYOND_MAX = 0.5  # ... or, the resonance above the band, below 0.5 x the band's top (scale known within 1.15)
QUASI_STATIC, QUASI_STATIC_SPREAD = 0.25, 1.25  # one mode's rise over the first quarter, within 1.25


@dataclass(frozen=True)
class LowRatio:
    """The response/base ratio at the band's bottom.

    Attributes
    ----------
    f_low : float
        Drive frequency of the band's three lowest windows (Hz, their median).
    ratio : float
        |H| there (the median of the three).
    f_peak : float
        Drive frequency where |H| peaks (Hz), or the band's top when `beyond`.
    beyond : bool
        True when |H| still rises at the band's top: the resonance is at or above `f_peak`.
    """

    f_low: float
    ratio: float
    f_peak: float
    beyond: bool = False

    @property
    def scale(self) -> float:
        """The response's values over its values in the base's unit: |H| less one mode's rise (geometric middle of
        the bounds when `beyond`)."""
        low = self.ratio * (1.0 - (self.f_low / self.f_peak) ** 2)
        return float(np.sqrt(low * self.ratio)) if self.beyond else low

    @property
    def rise(self) -> float:
        """One mode's rise at `f_low`, ``1 / (1 - (f_low / f_peak)^2)`` (at most that when `beyond`)."""
        return 1.0 / (1.0 - (self.f_low / self.f_peak) ** 2)


def response_ratio(ref: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                   rate: float) -> LowRatio | str:
    """The response/base ratio at the bottom of the band, or why the record cannot give it.

    Parameters
    ----------
    ref, resp : ndarray of float, shape (n,)
        Base and response accelerations (any one unit), from the sweep's start.
    fs : float
        Sample rate (Hz).
    f0, f1, rate : float
        The manifest's linear sweep (Hz, Hz, Hz/s).

    Returns
    -------
    LowRatio or str
        The ratio; or, in words, why not: too few windows, |H| largest at the band's
        bottom (no resonance above it), the band starting above ``LOW_RATIO_MAX`` x the
        resonance (``BEYOND_MAX`` x the band's top when |H| still rises there), or the
        ratio over the first ``QUASI_STATIC`` of the way to the peak not following one
        mode's rise within ``QUASI_STATIC_SPREAD`` (another mode down there).

    Notes
    -----
    In each window of ``MIN_CYCLES`` drive cycles the response is fitted by least squares
    as ``a x + b H[x]`` (x the base, H[x] its Hilbert transform, in quadrature with it):
    ``|H| = hypot(a, b)``, insensitive to noise and to a free vibration at another frequency.
    """
    k, m = windows(ref.size, fs, f0, f1, rate)
    if m < 5:
        return f"the sweep holds {m} windows of 20 drive cycles, fewer than 5"
    x = np.nan_to_num(ref - np.nanmedian(ref))
    y = np.nan_to_num(resp - np.nanmedian(resp))
    hx = quadrature(x)
    n, tsum, a11, a12, a22, b1, b2 = sums(k, m, np.ones(k.size), np.arange(k.size) / fs, x * x, x * hx, hx * hx,
                                          x * y, hx * y)
    det = a11 * a22 - a12**2
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = np.hypot(a22 * b1 - a12 * b2, a11 * b2 - a12 * b1) / det
        centre = tsum / n
    f = f0 + np.sign(f1 - f0) * rate * centre
    ok = np.isfinite(gain) & (det > 0) & (n >= 8)
    if ok.sum() < 5:
        return "fewer than 5 windows hold a base signal"
    f, gain = f[ok], gain[ok]
    order = np.argsort(f)
    f, gain = f[order], gain[order]
    k = int(np.argmax(gain))
    low = slice(0, 3)
    f_low, ratio = float(np.median(f[low])), float(np.median(gain[low]))
    if k == 0:
        return f"the response/base ratio is largest at the band's bottom ({f[0]:.0f} Hz): no resonance above it"
    beyond = k == f.size - 1
    f_peak = float(f[k])
    if beyond and f_low > BEYOND_MAX * f_peak:
        return (f"the ratio still rises at the band's top ({f_peak:.0f} Hz) and the band starts at "
                f"{f_low / f_peak:.2f} of it (the resonance's rise there is unknown)")
    if not beyond and f_low > LOW_RATIO_MAX * f_peak:
        return f"the band starts at {f_low / f_peak:.2f} of the resonance ({f_peak:.0f} Hz), above {LOW_RATIO_MAX}"
    below = (f <= f_low + QUASI_STATIC * (f_peak - f_low)) & (f < f_peak)
    if below.sum() < 3:
        return "fewer than 3 windows lie in the bottom quarter of the way to the resonance"
    if beyond:  # |H| rises by at most one mode's rise with its resonance at the band's top
        allowed = QUASI_STATIC_SPREAD / (1.0 - (f[below].max() / f_peak) ** 2)
        spread = gain[below].max() / gain[below].min()
    else:
        rise = gain[below] * (1.0 - (f[below] / f_peak) ** 2)
        allowed, spread = QUASI_STATIC_SPREAD, rise.max() / rise.min()
    if spread > allowed:
        return (f"the ratio over the band's bottom ({f_low:.0f}-{f[below].max():.0f} Hz) does not follow one mode's "
                "rise (another mode there?)")
    return LowRatio(f_low, ratio, f_peak, beyond)


def low_frequency_ratio(ref: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                        rate: float) -> tuple[float, float, float] | None:
    """``(f_low, ratio, f_peak)`` of `response_ratio` when the resonance lies within the band, else None."""
    low = response_ratio(ref, resp, fs, f0, f1, rate)
    return None if isinstance(low, str) or low.beyond else (low.f_low, low.ratio, low.f_peak)
