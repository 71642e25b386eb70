"""A response channel that does not respond to the drive: a dead or unplugged sensor reading an offset and noise.

Private: `jointcal.io._checks.validate_run` reports what `dead_problem` finds as the flag
``dead`` (in `jointcal.io.UNUSABLE_FLAGS`: such a run is not used for calibration).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from jointcal.io._windows import quadrature, sums, windows
from jointcal.io._contract import RESPONSE

__all__ = ["drive_share", "dead_problem", "DEAD_SHARE"]

# a live response follows its drive with most of its power (the example campaign: > 0.99); a sensor reading
# an offset and noise only: ~2 / (samples per window), 0.01 on the example's windows
DEAD_SHARE = 0.1


def drive_share(drive: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                rate: float) -> float:
    """The share of the response's power over the sweep that follows the drive.

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
    float
        ``sum_w fit_w / sum_w total_w`` (0 to 1), where in each window w of ``MIN_CYCLES``
        drive cycles the mean-removed response (power ``total_w``) is fitted by least squares
        as ``a x + b H[x]`` (x the drive, H[x] its Hilbert transform; power ``fit_w``): a
        response at the drive's frequency, of any amplitude and phase, changing from window
        to window. Noise alone gives about 2 / (samples per window). NaN when the sweep holds
        no whole window.
    """
    k, m = windows(drive.size, fs, f0, f1, rate)
    if m < 1:
        return float("nan")
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
    return float(np.clip(fit[ok].sum() / total[ok].sum(), 0.0, 1.0)) if ok.any() and total[ok].sum() > 0 \
        else float("nan")


def dead_problem(drive: NDArray[np.float64], resp: NDArray[np.float64], fs: float, f0: float, f1: float,
                 rate: float, path: object, drop: str,
                 source: Mapping[str, str]) -> list[tuple[str, str]]:
    """(flag, sentence) when less than ``DEAD_SHARE`` of the response's power over the sweep follows the drive."""
    share = drive_share(drive, resp, fs, f0, f1, rate)
    if not share < DEAD_SHARE:  # NaN: nothing to decide on
        return []
    name = source.get("name", RESPONSE)
    said = f" (channel {name!r} of the file)" if name != RESPONSE else ""
    finite = resp[np.isfinite(resp)]
    return [(f"dead:{RESPONSE}",
             f"{path}: column '{RESPONSE}'{said} does not respond to the drive ({share:.1%} of its power over the "
             f"sweep follows it; it reads {np.mean(finite):.3g} g +/- {np.std(finite):.3g} g, "
             f"an offset and noise); check the accelerometer, its cable and the channel's assignment and repeat "
             f"the run {drop}.")]
