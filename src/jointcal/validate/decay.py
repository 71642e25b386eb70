"""A ring-down validated as it was done: the model's free decay from the record's state at the cut-off.

The steps, in the order data flows (`decay_from_cut`, then `compare_decay`):

1. **The model's input** (`decay_input`): the record's reference as the model's input (`model_input`: a base
   acceleration as it is; a force or voltage through the campaign's modal constant), zero from where the
   record's decay starts (the drive cut), so that the model's own free decay starts from the steady state the measured dwell (or the
   impact) left it in. A record whose reference holds no drive (a ring-down whose drive file is missing; an
   impact not recorded), or a force or voltage the model cannot be driven by (no modal constant: a campaign of
   ring-downs alone has no swept-mode fit and no level of dwells), is given a held sine at the measured decay's
   first frequency, cut at the decay's start.
2. **The state at the cut-off** (`decay_from_cut`): the input is scaled by a factor c until the model's decay,
   read at the measured decay's first window, has the measured amplitude there (within `TOL`; a secant in log c,
   at most `TRIES` simulations). The exact Iwan (`jointcal.models.simulate`) starts from rest, so the joint's
   state at the cut (its steady hysteresis loop) is reached the way the structure reached it: by a dwell. c is
   1 for a model that reaches the measured amplitude under the measured drive; its departure from 1 is a misfit
   of the dwell, which the dwell's own FRF point measures (`jointcal.validate.steady`).
3. **The same read-out** (`jointcal.measure.ringdown.ringdown_at`): the model's decay read by the measurement's
   estimator (its band-pass, decay start and window fit) at the measured decay's windows, so the window-length
   bias (1-3% in zeta against closed forms) is the same in both and cancels.
4. **The comparison** (`compare_decay`): at each measured window, the model's f and zeta at the same amplitude
   (interpolated in log q along the model's decay), as relative errors over the read-out's own uncertainty,
   never less than the sweeps' floors in the same convention (`scales`). The decay envelope in time, the ratio
   of the amplitudes at each window, is reported beside them.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..io.contract import REFERENCE
from ..measure.ringdown import ringdown_at
from ..measure.testkinds.ringdown import METHOD as PART
from ..measure.testkinds.ringdown import window_scales
from ..models import MinistackModel
from .drive import model_input, reference_column, response_to

__all__ = ["decay_input", "decay_from_cut", "scales", "compare_decay", "TOL", "TRIES", "RAMP", "BEYOND", "PART"]

TOL = 0.002  # the model's first decay window's amplitude within this share of the measured one's
TRIES = 8  # simulations at most to reach it
RAMP = 0.25  # share of a held sine's length over which it rises (raised cosine): a start without a transient
BEYOND = 0.05  # a measured window's amplitude up to this share beyond the model's decay's takes the nearest


def decay_input(record: pd.DataFrame, row: Mapping, start: int, f_hz: float) -> tuple[NDArray[np.float64], bool, str]:
    """The model's input (g, shape (N,)) before its scaling, whether its response is the relative one, and how
    it was made.

    Parameters
    ----------
    record : DataFrame
        The measured record (time_s, its reference channel, response_accel_g).
    row : mapping
        Its manifest row (``sample_rate_hz``; ``drive_gain`` for a force or voltage reference).
    start : int
        The decay's first sample.
    f_hz : float
        The measured decay's frequency at its start (Hz): a held sine's.

    Returns
    -------
    x : ndarray, shape (N,)
        The input, a base acceleration (g): `model_input` up to `start` and zero from it on (the record's
        reference there is its DAQ's noise, which would drive the model's mode as no free decay is driven), or
        a held sine of 1 g that rises over `RAMP` of its length and stops at `start`.
    relative : bool
        A force or voltage reference (the model's fixed base forced by -m x: its response is the mass's
        acceleration relative to the base, `response_to`).
    source : {'reference', 'held sine'}
    """
    col = reference_column(record)
    ref = record[col].to_numpy(float)
    fin = ref[np.isfinite(ref)]
    relative = col != REFERENCE["base"]
    gain_known = not relative or row.get("drive_gain") is not None  # a force or voltage drives through it
    if fin.size and np.abs(fin - np.median(fin)).max() > 0 and gain_known:
        x = model_input(record, row)[0].copy()
        x[start:] = 0.0  # a free decay: the recorded drive's noise after the cut is no motion of the model's base
        return x, relative, "reference"
    fs = float(row["sample_rate_hz"])
    t = np.arange(len(record)) / fs
    ramp = max(1, int(RAMP * start))
    rise = 0.5 * (1 - np.cos(np.pi * np.clip(np.arange(len(record)) / ramp, 0, 1)))
    return np.where(np.arange(len(record)) < start, rise * np.sin(2 * np.pi * f_hz * t), 0.0), relative, "held sine"


def decay_from_cut(model: MinistackModel, record: pd.DataFrame, row: Mapping, windows: pd.DataFrame, f_hz: float,
                   start: int, *, first: NDArray | None = None) -> dict:
    """The model's free decay from the record's state at the cut-off, read at the measured decay's windows.

    Parameters
    ----------
    model : MinistackModel
    record, row : DataFrame, mapping
        The measured record and its manifest row (see `decay_input`).
    windows : DataFrame
        The measured decay's read-out (`jointcal.measure.ringdown.ringdown_backbone`: t_s, window_s, q_in, f_hz).
    f_hz : float
        The frequency the measured decay was read at (Hz; the modal stage's, `mode_peak_hz`).
    start : int
        The measured decay's first sample (the same for the model's: the drive is cut where it was).
    first : ndarray, shape (N,), optional
        The model's response (g) to the unscaled input, when already simulated (a dwell's FRF point).

    Returns
    -------
    dict
        ``response_g`` (the model's response at the scale used, shape (N,)), ``windows`` (its read-out at
        `windows`, `ringdown_at`), ``scale`` (c), ``source`` (`decay_input`'s), ``converged`` (the first
        window's amplitude within `TOL`), ``tries`` (simulations run).
    """
    if windows.empty:
        raise ValueError("the measured decay has no window read: there is no decay to compare the model's with.")
    x, relative, source = decay_input(record, row, start, float(windows["f_hz"].iloc[0]))
    fs = float(row["sample_rate_hz"])
    top = windows.iloc[:1]
    q_m = float(top["q_in"].iloc[0])
    c, tried, y = 1.0, [], first if source == "reference" else None
    for k in range(TRIES):
        if y is None or k > 0:
            y = response_to(model, c * x, fs, relative=relative)
        q_s = float(ringdown_at(y, fs, f_hz, top, start=start)["q_in"].iloc[0])
        tried.append((c, q_s))
        if abs(q_s / q_m - 1) <= TOL or not (np.isfinite(q_s) and q_s > 0):
            break
        slope = 1.0  # d log q / d log c: 1 for a linear model; from the last two tries after that
        if len(tried) > 1 and tried[-1][0] != tried[-2][0] and tried[-1][1] != tried[-2][1]:
            slope = float(np.clip(np.log(tried[-1][1] / tried[-2][1]) / np.log(tried[-1][0] / tried[-2][0]),
                                  0.3, 3.0))
        c *= (q_m / q_s) ** (1.0 / slope)
    return {"response_g": y, "windows": ringdown_at(y, fs, f_hz, windows, start=start), "scale": tried[-1][0],
            "source": source, "converged": abs(tried[-1][1] / q_m - 1) <= TOL, "tries": len(tried)}


def scales(windows: pd.DataFrame, *, floor_db: float, floor_deg: float) -> tuple[NDArray, NDArray]:
    """Each window's scale of the relative errors in f and zeta: the read-out's own standard errors
    (``f_se_hz`` / f, ``zeta_se`` / zeta), never less than the sweeps' floors in the same convention
    (`jointcal.measure.testkinds.ringdown.window_scales`, which the calibration's polish weighs windows by).

    Returns
    -------
    sigma_f, sigma_zeta : ndarray, shape (len(windows),)
    """
    return window_scales(*(windows[c].to_numpy(float) for c in ("f_hz", "zeta", "f_se_hz", "zeta_se")),
                         floor_db=floor_db, floor_deg=floor_deg)


def compare_decay(meas: pd.DataFrame, sim: pd.DataFrame, *, floor_db: float = 0.05,
                  floor_deg: float = 0.3) -> tuple[pd.DataFrame, dict]:
    """The model's decay against the measured one, window by window, at the same amplitude.

    Parameters
    ----------
    meas : DataFrame
        The measured decay's windows (`ringdown_backbone`: t_s, window_s, q_in, f_hz, zeta, zeta_se, f_se_hz).
    sim : DataFrame
        The model's decay read at the same windows (`ringdown_at`).
    floor_db, floor_deg : float
        The sweeps' floors (`scales`).

    Returns
    -------
    frames : DataFrame, one row per measured window
        ``part`` ('ringdown'), t_s, window_s, q_meas_in, q_sim_in (the model's amplitude at the same time, in),
        d_env_db (20 log10 of their ratio: the decay envelope), f_meas_hz, f_sim_hz, zeta_meas, zeta_sim (the
        model's at the measured amplitude, interpolated in log q), d_f_rel, d_zeta_rel (simulated / measured - 1),
        sigma_f_rel, sigma_zeta_rel (`scales`), r_f, r_zeta (the errors over their scales), in_range (the
        measured amplitude within the model's decay's, up to `BEYOND` beyond it, where the model's nearest
        window's f and zeta stand: the last measured window, at the noise, reads its amplitude a few per cent
        off, and the backbone is flat at the small amplitudes).
    metrics : dict
        n_windows (compared), decades, q_first_meas_in, q_first_sim_in, f_rel_err_mean, f_rel_err_rms,
        zeta_rel_err_mean, zeta_rel_err_rms, env_end_db (at the last window), E_f, E_zeta (rms of r_f and
        r_zeta).
    """
    q_m, q_s = meas["q_in"].to_numpy(float), sim["q_in"].to_numpy(float)
    ok = np.isfinite(q_s) & (q_s > 0) & (sim["zeta"].to_numpy(float) > 0)
    o = np.argsort(np.log(q_s[ok]))
    lq = np.log(q_s[ok])[o]
    at = lambda col: np.interp(np.log(q_m), lq, sim[col].to_numpy(float)[ok][o]) if lq.size else np.nan  # noqa: E731
    f_s, z_s = at("f_hz"), at("zeta")
    inside = ((q_m >= np.exp(lq[0]) * (1 - BEYOND)) & (q_m <= np.exp(lq[-1]) * (1 + BEYOND)) if lq.size
              else np.zeros(q_m.size, bool))
    sf, sz = scales(meas, floor_db=floor_db, floor_deg=floor_deg)
    d_f, d_z = f_s / meas["f_hz"].to_numpy(float) - 1, z_s / meas["zeta"].to_numpy(float) - 1
    frames = pd.DataFrame(dict(
        part=PART, t_s=meas["t_s"].to_numpy(float), window_s=meas["window_s"].to_numpy(float), q_meas_in=q_m,
        q_sim_in=q_s, d_env_db=20 * np.log10(q_s / q_m), f_meas_hz=meas["f_hz"].to_numpy(float), f_sim_hz=f_s,
        zeta_meas=meas["zeta"].to_numpy(float), zeta_sim=z_s, d_f_rel=d_f, d_zeta_rel=d_z, sigma_f_rel=sf,
        sigma_zeta_rel=sz, r_f=d_f / sf, r_zeta=d_z / sz, in_range=inside))
    b = frames[frames["in_range"]]
    rms = lambda v: float(np.sqrt(np.mean(v**2))) if len(v) else np.nan  # noqa: E731
    mean = lambda v: float(np.mean(v)) if len(v) else np.nan  # noqa: E731
    metrics = {"n_windows": int(len(b)), "decades": float(np.log10(q_m.max() / q_m.min())) if q_m.size else np.nan,
               "q_first_meas_in": float(q_m[0]) if q_m.size else np.nan,
               "q_first_sim_in": float(q_s[0]) if q_s.size else np.nan,
               "f_rel_err_mean": mean(b["d_f_rel"]), "f_rel_err_rms": rms(b["d_f_rel"]),
               "zeta_rel_err_mean": mean(b["d_zeta_rel"]), "zeta_rel_err_rms": rms(b["d_zeta_rel"]),
               "env_end_db": float(frames["d_env_db"].iloc[-1]) if len(frames) else np.nan,
               "E_f": rms(b["r_f"]), "E_zeta": rms(b["r_zeta"])}
    return frames, metrics
