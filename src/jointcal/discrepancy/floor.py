"""The fast model's own error: its envelope of the calibrated model against that model's time simulation.

The validation stage simulates the calibrated model in time, driven by each run's measured
reference record, and measures the simulated record with the same envelopes (`jointcal.validate`).
On those runs and frames (the compared band) the fast model (`fit.predict`: the swept
envelope model) gives the same model's envelope; their difference, in the validation's
definition of E (per-bin repeat scatter, every run weighted equally), is the floor below
which the fast model cannot tell a missing effect from its own approximation. Reported
per level and overall; the decision takes it out of the baseline's score
(`rule.decide`), and the diagnosis states it.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..validate.drive import equivalent_base
from ..validate.error import BINS
from .data import RunEnvelope, run_zeta
from .fit import Candidate, Objective

__all__ = ["fast_floor"]


def _at_frames(run: RunEnvelope, frame: pd.DataFrame, sdb: NDArray, sdeg: NDArray) -> RunEnvelope | None:
    """The run at the validation's compared frames (the fast model needs the drive there)."""
    fr = frame[frame["in_band"]] if "in_band" in frame else frame
    if run.drive is None or fr.empty:
        return None
    t = fr["time_s"].to_numpy(float)
    inside = (t >= run.drive.t_s[0]) & (t <= run.drive.t_s[-1])
    if not inside.any():  # a fast chirp leaves two or three compared frames: each counts
        return None
    fr, t = fr[inside], t[inside]
    f, base, _, _ = run.drive.at(t)
    T = 10 ** (fr["mag_sim_db"].to_numpy(float) / 20) * np.exp(1j * np.radians(fr["phase_sim_deg"].to_numpy(float)))
    x = np.abs(fr["f_hz"].to_numpy(float) / float(run.row["f_res_hz"]) - 1.0) / run_zeta(run.row)
    b = np.clip(np.digitize(x, BINS[1:-1]), 0, len(BINS) - 2)
    f = fr["f_hz"].to_numpy(float)
    eq = None if run.equivalent_base is None else equivalent_base(run.row, f)
    return replace(run, f_hz=f, base_g=base, T=T, sigma_db=sdb[b], sigma_deg=sdeg[b], t_s=t,
                   equivalent_base=eq)


def fast_floor(c: Candidate, theta: NDArray, runs: Sequence[RunEnvelope], frames: Mapping[str, pd.DataFrame],
               sigma_db: NDArray, sigma_deg: NDArray) -> dict:
    """E of the fast model's envelope of `theta` against the time simulation of the same model.

    Parameters
    ----------
    c, theta : Candidate, ndarray (n,)
        The calibrated model (the baseline at the calibration's parameters).
    runs : sequence of RunEnvelope
        The assembly's runs (their drive and modal row).
    frames : mapping run_id -> DataFrame
        The validation's compared frames of that same model (`compare_run`: time_s, f_hz,
        mag_sim_db, phase_sim_deg, in_band).
    sigma_db, sigma_deg : ndarray, shape (len(BINS) - 1,)
        The repeat scatter per bin.

    Returns
    -------
    dict
        E, E_mag, E_phase, n_runs, per_level {level: E}, per_run {run_id: E}; E None when no
        run could be compared.
    """
    rows = []
    for run in runs:
        rid = run.row["run_id"]
        at = _at_frames(run, frames[rid], sigma_db, sigma_deg) if rid in frames else None
        if at is None:
            continue
        d = Objective(c, [at]).at(theta).predict(theta, 0) / at.T
        rows.append((rid, at.level, np.mean((20 * np.log10(np.abs(d)) / at.sigma_db) ** 2),
                     np.mean((np.degrees(np.angle(d)) / at.sigma_deg) ** 2)))
    if not rows:
        return {"E": None, "E_mag": None, "E_phase": None, "n_runs": 0, "per_level": {}, "per_run": {}}
    t = pd.DataFrame(rows, columns=["run_id", "level", "m2", "p2"])
    e = lambda g: float(np.sqrt((g["m2"].mean() + g["p2"].mean()) / 2))  # noqa: E731
    return {"E": e(t), "E_mag": float(np.sqrt(t["m2"].mean())), "E_phase": float(np.sqrt(t["p2"].mean())),
            "n_runs": int(len(t)), "per_level": {f"{k:g}": e(g) for k, g in t.groupby("level")},
            "per_run": {r.run_id: float(np.sqrt((r.m2 + r.p2) / 2)) for r in t.itertuples()}}
