"""Equal-amplitude line pairs of a bent FRF peak: the equivalent-linear pole at each amplitude.

A voltage reference's modal constant has an unknown phase, and a nonlinear joint bends the
peak; `pair_backbone` reads the pole from pairs of lines of equal |X| below and above the
peak, without the modal constant, and `backbone_at_peak` extrapolates it to the peak's
amplitude.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.optimize import brentq

__all__ = ["pair_backbone", "backbone_at_peak"]


def pair_backbone(f: NDArray, X: NDArray, levels: NDArray = np.linspace(0.5, 0.9, 17), *,
                  f_guess: float | None = None, near_frac: float = 0.1) -> pd.DataFrame:
    """Equivalent-linear frequency and damping at several amplitudes, from equal-amplitude line pairs.

    For a drive of constant amplitude (an amplifier's voltage) each line of a quasi-steady
    sweep's ratio X = x / ref is the equivalent-linear (first-harmonic) FRF frozen at the
    amplitude q the structure had there, and q is proportional to |X|. At a level s of the
    peak, the line w_1 below and w_2 above the peak with |X| = s |X|_peak see the SAME frozen
    FRF A / (Omega^2 - w^2 + i D w), so

        Omega^2 = (w_1^2 + w_2^2 + D^2) / 2                      (|X(w_1)| = |X(w_2)|)
        arg X(w_1) - arg X(w_2) = arg[(Omega^2 - w_2^2 + i D w_2) / (Omega^2 - w_1^2 + i D w_1)]

    which give Omega and D at that amplitude without the modal constant A (its phase cancels:
    an amplifier voltage's phase to the force is unknown). zeta = D / (2 Omega). For a linear
    structure every level gives the same exact pole; for a softening joint Omega falls and zeta
    grows towards the peak: the backbone over the amplitudes the peak region spans.

    Parameters
    ----------
    f : ndarray, Hz;  X : complex ndarray
        Displacement ratio on increasing lines (`displacement_ratio`), the peak region included.
    levels : ndarray
        Fractions s of the peak |X| (0 < s < 1) at which pairs are taken.
    f_guess : float, optional
        The largest |X| within f_guess (1 +- near_frac) (Hz) instead of the largest overall.

    Returns
    -------
    DataFrame, one row per level resolved
        level (s), f1_hz, f2_hz (the pair), f_hz (Omega / 2 pi), zeta. Levels whose pair
        leaves the lines, or whose phase difference no damping reproduces, are left out.

    Notes
    -----
    Assumes the modal constant constant across the pair and no other mode nearby (an
    amplifier's coil inductance turns A by -(L/R) / (1 + (w L/R)^2) rad per rad/s: about 1% of
    the phase difference on the synthetic Ministack rig), and quasi-steady lines: a sweep too
    fast for the nonlinear structure to follow (eta above ~5) breaks the line-amplitude map.
    """
    ok = np.isfinite(X)
    f, X = np.asarray(f, float)[ok], np.asarray(X)[ok]
    a = np.abs(X)
    near = np.ones(a.size, bool) if f_guess is None else np.abs(f / f_guess - 1) <= near_frac
    ip = int(np.flatnonzero(near)[np.argmax(a[near])]) if near.any() else int(np.argmax(a))
    s = a / a[ip]
    ph = np.unwrap(np.angle(X))
    rows = []
    for lv in np.atleast_1d(levels):
        lo, hi = np.flatnonzero(s[:ip] < lv), np.flatnonzero(s[ip:] < lv)
        if not (lo.size and hi.size):
            continue
        i, j = lo[-1], ip + hi[0] - 1  # crossings between lines i, i+1 (rising) and j, j+1 (falling)
        u, v = (lv - s[i]) / (s[i + 1] - s[i]), (lv - s[j]) / (s[j + 1] - s[j])
        f1, f2 = f[i] + u * (f[i + 1] - f[i]), f[j] + v * (f[j + 1] - f[j])
        dphi = (ph[i] + u * (ph[i + 1] - ph[i])) - (ph[j] + v * (ph[j + 1] - ph[j]))
        w1, w2 = 2 * np.pi * f1, 2 * np.pi * f2

        def gap(D):
            o2 = 0.5 * (w1**2 + w2**2 + D**2)
            return np.angle((o2 - w2**2 + 1j * D * w2) / (o2 - w1**2 + 1j * D * w1)) - dphi

        lo_d, hi_d = 1e-6 * w1, 2.0 * w1
        if not (w2 > w1 and gap(lo_d) * gap(hi_d) < 0):
            continue
        D = brentq(gap, lo_d, hi_d, xtol=1e-12 * w1)
        om = np.sqrt(0.5 * (w1**2 + w2**2 + D**2))
        rows.append(dict(level=float(lv), f1_hz=float(f1), f2_hz=float(f2), f_hz=float(om / (2 * np.pi)),
                         zeta=float(D / (2 * om))))
    return pd.DataFrame(rows, columns=["level", "f1_hz", "f2_hz", "f_hz", "zeta"])


def backbone_at_peak(bb: pd.DataFrame, *, min_levels: int = 5) -> tuple[float, float, float]:
    """The pair backbone extrapolated to the peak's amplitude (s = 1): frequency (Hz), zeta, spread.

    A straight line in s through the levels (least squares), evaluated at s = 1: the
    equivalent-linear pole at the amplitude of the peak, i.e. at the run's steady-state
    level for a slow sweep. spread: the RMS relative misfit of that line to the levels'
    frequencies (how far the backbone is from straight over 0.5-0.9 of the peak).
    NaNs when fewer than `min_levels` levels were resolved.
    """
    if len(bb) < min_levels:
        return float("nan"), float("nan"), float("nan")
    s = bb["level"].to_numpy()
    cf, cz = np.polyfit(s, bb["f_hz"], 1), np.polyfit(s, bb["zeta"], 1)
    spread = float(np.sqrt(np.mean((np.polyval(cf, s) / bb["f_hz"].to_numpy() - 1) ** 2)))
    return float(np.polyval(cf, 1.0)), float(np.polyval(cz, 1.0)), spread
