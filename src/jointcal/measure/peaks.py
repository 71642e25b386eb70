"""Small read-outs every measurement shares, each written once.

* `half_power_lines` and `half_power`: the lines where a peak falls below 1/sqrt(2) of
  its height on each side, and the half-power frequencies interpolated between lines.
* `anchored_phase` and `phase_crossing`: an unwrapped phase moved by whole turns so that
  its median lies within half a turn of a target, and where it crosses the target
  (quadrature: +90 deg for a relative displacement over a base acceleration, -90 deg for a
  receptance over its modal constant; docs/physics.md, "Phase quadrature").
* `full_drive` and `transmissibility`: the envelope frames at full drive (a controlled
  drive's start and stop ramps left out) and the response over the reference, frame by frame.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray

__all__ = ["half_power_lines", "half_power", "anchored_phase", "phase_crossing",
           "full_drive", "transmissibility", "envelope"]

FULL_DRIVE = 0.8  # frames whose reference is at least this fraction of its median are at full drive


def half_power_lines(a: NDArray[np.float64], ip: int) -> tuple[int | None, int | None]:
    """The last line below and the first line above the peak `ip` where ``a < a[ip] / sqrt(2)``; None if none.

    Parameters
    ----------
    a : ndarray, shape (n,)
        A magnitude (any unit) on increasing frequency lines.
    ip : int
        Index of the peak.
    """
    level = a[ip] / np.sqrt(2.0)
    left, right = np.flatnonzero(a[:ip] < level), np.flatnonzero(a[ip:] < level)
    return (int(left[-1]) if left.size else None), (ip + int(right[0]) if right.size else None)


def half_power(f: NDArray[np.float64], a: NDArray[np.float64], ip: int) -> tuple[float, float]:
    """Half-power frequencies (Hz) around the peak `ip` of the magnitude `a(f)`, interpolated; NaN if not found.

    The damping ratio of a single mode is ``(f_hi - f_lo) / (2 f_peak)`` (docs/physics.md,
    "Half-power bandwidth").
    """
    level = a[ip] / np.sqrt(2.0)
    i, j = half_power_lines(a, ip)
    lo = np.nan if i is None else f[i] + (level - a[i]) * (f[i + 1] - f[i]) / (a[i + 1] - a[i])
    hi = np.nan if j is None else f[j - 1] + (level - a[j - 1]) * (f[j] - f[j - 1]) / (a[j] - a[j - 1])
    if not np.isfinite(lo + hi):  # one side missing: no bandwidth (min/max would pass the found side twice)
        return np.nan, np.nan
    return min(lo, hi), max(lo, hi)


def anchored_phase(z: NDArray[np.complex128], target: float) -> NDArray[np.float64]:
    """Unwrapped phase of `z` (rad), moved by whole turns so that its median lies within pi of `target`."""
    ph = np.unwrap(np.angle(z))
    return ph + 2 * np.pi * np.round((target - np.median(ph)) / (2 * np.pi))


def phase_crossing(f: NDArray[np.float64], ph: NDArray[np.float64], target: float,
                   f_near: float) -> tuple[int, float] | None:
    """Where the phase `ph(f)` crosses `target` nearest `f_near` (Hz): (i, w), the crossing at i + w.

    Interpolate any quantity there as ``x[i] + w (x[i + 1] - x[i])``. None when the phase
    never reaches the target.
    """
    d = ph - target
    cands = np.flatnonzero((d[:-1] == 0) | (d[:-1] * d[1:] < 0))
    if not cands.size:
        return None
    i = int(cands[np.argmin(np.abs(f[cands] - f_near))])
    return i, ((target - ph[i]) / (ph[i + 1] - ph[i]) if ph[i + 1] != ph[i] else 0.0)


def envelope(env: pd.DataFrame, name: str) -> NDArray[np.complex128]:
    """The complex envelope ``<name>_re + i <name>_im`` of an envelope table ('ref', 'resp' or 'z')."""
    return (env[f"{name}_re"] + 1j * env[f"{name}_im"]).to_numpy()


def transmissibility(env: pd.DataFrame) -> NDArray[np.complex128]:
    """Response over reference of each envelope frame (g/g for a base drive; g/lbf, g/V otherwise)."""
    return ((env["resp_re"] + 1j * env["resp_im"]) / (env["ref_re"] + 1j * env["ref_im"])).to_numpy()


def full_drive(env: pd.DataFrame, fraction: float = FULL_DRIVE) -> NDArray[np.bool_]:
    """Frames that are drive-on, not bad, and at full drive: ``|ref| >= fraction x`` its median over those frames.

    0.8 leaves out a controlled drive's start and stop ramps, where a ringing response is
    divided by a vanishing reference; an open-loop force drops out at resonance by physics
    and takes a small fraction (the validation stage: 0.05).
    """
    ref = np.abs(envelope(env, "ref"))
    on = env["drive_on"].to_numpy(bool) & ~env["bad"].to_numpy(bool)
    return on & (ref >= fraction * np.median(ref[on])) if on.any() else on
