"""A response channel that does not respond to the drive: a dead or unplugged sensor reading an offset and noise.

Private: `jointcal.io._checks.validate_run` reports what `dead_problem` finds as the flag
``dead`` (in `jointcal.io.UNUSABLE_FLAGS`: such a run is not used for calibration).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from jointcal.io._windows import quadrature, sums, windows
from jointcal.io.contract import RESPONSE

__all__ = ["drive_share", "dead_problem", "DEAD_SHARE", "NOISE_TIMES"]

# noise alone has a share of chi^2(2 m) / N (m windows, N samples: mean 2 m / N, relative spread 1 / sqrt(m));
# a response is dead below this many times that mean (and never above DEAD_SHARE). Live responses: the example
# campaign > 0.999 (noise alone 0.0125); the real UNESP beam's fast chirps, ringing at their mode after its
# passage, 0.15-0.20 (noise alone 0.002)
NOISE_TIMES, DEAD_SHARE = 3.0, 0.1


def drive_share(drive: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                rate: float) -> tuple[float, float]:
    """The share of the response's power over the sweep that follows the drive, and what noise alone would give.

    Parameters
    ----------
    drive, resp : ndarray of float, shape (n,)
        The reference (any unit) and the response, from the sweep's start.
    fs : float
        Sample rate (Hz).
    f0, f1, rate : float
        The manifest's linear sweep (Hz, Hz, Hz/s).

    Returns
    -------
    share : float
        ``sum_w fit_w / sum_w total_w`` (0 to 1), where in each window w of ``MIN_CYCLES``
        drive cycles the mean-removed response (power ``total_w``) is fitted by least squares
        as ``a x + b H[x]`` (x the drive, H[x] its Hilbert transform; power ``fit_w``): a
        response at the drive's frequency, of any amplitude and phase, changing from window
        to window. NaN when the sweep holds no whole window.
    noise : float
        The share noise alone would have on average: two fitted coefficients per window,
        ``2 m / N`` (m windows of N samples in all).
    """
    k, m = windows(drive.size, fs, f0, f1, rate)
    if m < 1:
        return float("nan"), float("nan")
    x = np.nan_to_num(drive - np.nanmedian(drive))
    hx = quadrature(x)
    y = np.nan_to_num(resp - np.nanmedian(resp))[: x.size]
    n, a11, a12, a22, b1, b2, s1, s2 = sums(k, m, np.ones(k.size), x * x, x * hx, hx * hx, x * y, hx * y, y, y * y)
    det = a11 * a22 - a12**2
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (a22 * b1 - a12 * b2) / det
        b = (a11 * b2 - a12 * b1) / det
        fit, total = a * b1 + b * b2, s2 - s1**2 / n  # fitted and total (mean-removed) power
    ok = np.isfinite(fit) & np.isfinite(total) & (det > 0) & (n >= 8)
    if not ok.any() or total[ok].sum() <= 0:
        return float("nan"), float("nan")
    return float(np.clip(fit[ok].sum() / total[ok].sum(), 0.0, 1.0)), float(2 * ok.sum() / n[ok].sum())


def dead_problem(drive: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                 rate: float, path: object, drop: str,
                 source: Mapping[str, str]) -> list[tuple[str, str]]:
    """(flag, sentence) when the response's share that follows the drive is below ``NOISE_TIMES`` x that of noise
    alone (and ``DEAD_SHARE``)."""
    share, noise = drive_share(drive, resp, fs, f0, f1, rate)
    if not share < min(DEAD_SHARE, NOISE_TIMES * noise):  # NaN: nothing to decide on
        return []
    name = source.get("name", RESPONSE)
    said = f" (channel {name!r} of the file)" if name != RESPONSE else ""
    finite = resp[np.isfinite(resp)]
    return [(f"dead:{RESPONSE}",
             f"{path}: column '{RESPONSE}'{said} does not respond to the drive ({share:.1%} of its power over the "
             f"sweep follows it, as noise alone would ({noise:.1%}); it reads {np.mean(finite):.3g} g "
             f"+/- {np.std(finite):.3g} g, "
             f"an offset and noise); check the accelerometer, its cable and the channel's assignment and repeat "
             f"the run {drop}.")]
