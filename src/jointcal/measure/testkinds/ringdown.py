"""ringdown: a run read along its free decay; its row is the largest-amplitude window.

Each window carries its length (``window_s``) and its read-out's own standard errors (``f_se_hz``,
``zeta_se``): `SE_COLUMNS`, in backbone.csv beside its q, f and zeta; `window_scales` makes them the relative scales the validation
judges a window on and the calibration's polish weighs it by, never below the sweeps' floors.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .readout import Estimator, Readout, ReadoutRule, Refusal

__all__ = ["RULE", "WINDOWS", "METHOD", "MIN_DECAY_S", "SE_COLUMNS", "FLOOR_DB", "FLOOR_DEG", "window_scales", "window_top"]

METHOD = "ringdown"  # its f_res_method, and backbone.csv's ``test`` of every decay window (a dwell's too)
MIN_DECAY_S = 1.0  # a record this long after the cut holds a ring-down to read (as decay_start asks)
SE_COLUMNS = ("window_s", "f_se_hz", "zeta_se")  # a window's length (s), standard errors of f (Hz) and zeta
FLOOR_DB, FLOOR_DEG = 0.05, 0.3  # the sweeps' floors (the validation's defaults, `ValidateSettings`): dB, deg


def window_top(q_in: ArrayLike, f_hz: ArrayLike, zeta: ArrayLike, window_s: ArrayLike) -> NDArray[np.float64]:
    """The amplitude at the start of a window read at q_in (in): q_in exp(pi f zeta L), the decay
    exp(-2 pi f zeta t) over the half window L / 2 before its centre (f in Hz, L in s)."""
    q, f, z, L = (np.asarray(v, dtype=float) for v in (q_in, f_hz, zeta, window_s))
    return q * np.exp(np.pi * f * z * L)


def window_scales(f_hz: ArrayLike, zeta: ArrayLike, f_se_hz: ArrayLike, zeta_se: ArrayLike, *,
                  floor_db: float = FLOOR_DB, floor_deg: float = FLOOR_DEG
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each window's scale of the relative errors in f and zeta: its read-out's own standard errors, never less
    than the sweeps' floors in the same convention.

    A resonance's peak is proportional to 1 / zeta, so the magnitude floor ``floor_db`` is a relative damping
    10^(floor_db / 20) - 1 (0.05 dB: 0.58%); the phase at resonance turns by 1 / zeta rad per unit f / f_n, so
    the phase floor ``floor_deg`` is a relative frequency zeta floor_deg pi / 180 (0.3 deg at zeta 0.01: 5.2e-5).

    Parameters
    ----------
    f_hz, zeta : array_like, shape (N,)
        The windows' frequency (Hz) and damping ratio.
    f_se_hz, zeta_se : array_like, shape (N,)
        Their standard errors (Hz; damping ratio).
    floor_db, floor_deg : float
        The sweeps' floors of magnitude (dB) and phase (deg).

    Returns
    -------
    sigma_f, sigma_zeta : ndarray, shape (N,)
        Relative scales (dimensionless) of f and zeta.
    """
    f, z = np.asarray(f_hz, float), np.asarray(zeta, float)
    sigma_f = np.maximum(np.asarray(f_se_hz, float) / f, np.abs(z) * np.radians(floor_deg))
    sigma_z = np.maximum(np.asarray(zeta_se, float) / np.abs(z), 10 ** (floor_db / 20) - 1)
    return sigma_f, sigma_z


def _top_window(read) -> Readout | Refusal:
    w = read["windows"]
    if w is None or not len(w):  # the read's own flag (shaker_on) says why, where it has one
        return Refusal(f"no free decay of {MIN_DECAY_S:g} s or more", () if read["flags"] else ("no_decay",))
    top = w.loc[w["q_in"].idxmax()]
    return Readout({"f_res_hz": top["f_hz"], "zeta_res": top["zeta"], "q_in": top["q_in"]})


WINDOWS = Estimator(
    METHOD,
    "the largest-amplitude window of its free decay (ringdown): damped-sinusoid fits in sliding windows that "
    "lengthen as the decay nears the noise, one point per window down to the noise floor, read through the force with the modal constant the mode's sweep measured where a force "
    f"reference stays live after the cut (through_force), not read without a decay of {MIN_DECAY_S:g} s or more "
    "(no_decay) or where the shaker stays on and no sweep measured the mode (shaker_on)",
    _top_window)

RULE = ReadoutRule("ringdown", (WINDOWS,))
