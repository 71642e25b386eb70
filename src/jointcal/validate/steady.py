"""A dwell validated as it was done: the model's steady state under the measured drive, one FRF point.

The model is driven by the dwell's record (`jointcal.validate.drive.model_input`: a base acceleration as it is,
a force or voltage through the campaign's modal constant) and both records are read by the measurement's own
dwell read-out (`jointcal.measure.dwell.dwell_point`: a lock-in over the last half of the held drive), so the
steady amplitude and phase of response / reference compare as one point of the transmissibility, on the sweeps'
scale: its magnitude in dB and its phase in degrees over the point's own uncertainty (the change between the
halves of its read part, `dwell_point`'s ``change``), never less than the sweeps' floors.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..measure.testkinds.dwell import STEADY

__all__ = ["compare_dwell"]


def compare_dwell(meas: Mapping, sim: Mapping, *, floor_db: float = 0.05,
                  floor_deg: float = 0.3) -> tuple[pd.DataFrame, dict]:
    """The model's steady point against the measured one.

    Parameters
    ----------
    meas, sim : mapping
        `dwell_point`'s dicts of the measured and the simulated record (``f_hz``, ``ratio`` complex response g
        per reference unit, ``resp_amp_g``, ``q_in`` in, ``change``).
    floor_db, floor_deg : float
        The sweeps' floors of magnitude (dB) and phase (deg).

    Returns
    -------
    frame : DataFrame, one row
        ``part`` ('dwell'), f_hz, mag_meas_db, mag_sim_db (20 log10 |ratio|), phase_meas_deg, phase_sim_deg
        (of the ratio), d_mag_db, d_phase_deg (simulated relative to measured, the phase wrapped to
        (-180, 180]), sigma_mag_db, sigma_phase_deg, r_mag, r_phase (the errors over their scales),
        q_meas_in, q_sim_in (the displacement amplitudes reached).
    metrics : dict
        dwell_hz, dwell_mag_err_db, dwell_phase_err_deg, q_dwell_meas_in, q_dwell_sim_in, E_mag, E_phase
        (|r_mag|, |r_phase|).
    """
    h_m, h_s = complex(meas["ratio"]), complex(sim["ratio"])
    if not (abs(h_m) > 0 and np.isfinite(abs(h_m)) and np.isfinite(abs(h_s))):
        raise ValueError(f"the dwell at {meas['f_hz']:g} Hz has no steady response to compare (ratio {h_m!r}).")
    d = h_s / h_m
    change = float(meas.get("change", 0.0))
    s_db = max(floor_db, 20 * np.log10(1 + change))
    s_deg = max(floor_deg, float(np.degrees(change)))
    d_db, d_deg = 20 * np.log10(abs(d)), float(np.degrees(np.angle(d)))
    frame = pd.DataFrame([dict(
        part=STEADY.method, f_hz=float(meas["f_hz"]), mag_meas_db=20 * np.log10(abs(h_m)),
        mag_sim_db=20 * np.log10(abs(h_s)), phase_meas_deg=float(np.degrees(np.angle(h_m))),
        phase_sim_deg=float(np.degrees(np.angle(h_s))), d_mag_db=d_db, d_phase_deg=d_deg, sigma_mag_db=s_db,
        sigma_phase_deg=s_deg, r_mag=d_db / s_db, r_phase=d_deg / s_deg, q_meas_in=float(meas["q_in"]),
        q_sim_in=float(sim["q_in"]))])
    metrics = {"dwell_hz": float(meas["f_hz"]), "dwell_mag_err_db": d_db, "dwell_phase_err_deg": d_deg,
               "q_dwell_meas_in": float(meas["q_in"]), "q_dwell_sim_in": float(sim["q_in"]),
               "E_mag": abs(d_db / s_db), "E_phase": abs(d_deg / s_deg)}
    return frame, metrics
