"""Test helpers (not jointcal code): a virtual force-driven campaign of a jointed structure with two
amplitude-dependent modes, and each mode's truth.

The structure in modal coordinates (uncoupled modal Iwan joints, the modal-Iwan model of jointed
structures): two modes of unit modal mass at the driving point, each a spring k in parallel with its own
Iwan joint and a dashpot, driven by the same measured force F(t): m x_i'' + c_i x_i' + k_i x_i + F_iwan,i = F.
Each mode is integrated apart by the exact Iwan simulator (`jointcal.models.simulate`, the force given as
the base acceleration -F/m of a fixed-base oscillator); the driving point's acceleration is x_1'' + x_2''.
The truth of a mode at an amplitude q is its first-harmonic balance (`jointcal.models.harmonic_balance`).
Both channels carry 1% white noise (of the channel's rms), and the force is a prescribed-amplitude chirp
with 50 ms raised-cosine ramps.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.models import IwanParams, MinistackModel, harmonic_balance, simulate
from jointcal.units import G

# a 100 Hz mode and a 230 Hz mode, both with about 2% softening over the levels' amplitudes
MODES = {"low": dict(k=818.0, Fs=4.0, KT=204.0, chi=-0.5, beta=0.1, zeta_v=0.008, m=1.0 / G),
         "high": dict(k=4327.0, Fs=4.0, KT=1079.0, chi=-0.5, beta=0.1, zeta_v=0.006, m=1.0 / G)}
FS = 1024.0
LEVELS_LBF = (0.04, 0.12, 0.32)
# two families of runs: a wide chirp over both modes, a slow sweep over the upper one alone
FAMILIES = {"wide": dict(f_start_hz=60.0, f_stop_hz=300.0, rate=24.0),
            "upper": dict(f_start_hz=195.0, f_stop_hz=265.0, rate=8.0)}


def truth(mode: str, q) -> tuple[np.ndarray, np.ndarray]:
    """(f Hz, zeta) of one mode at amplitude q (in)."""
    p = MODES[mode]
    return harmonic_balance(q, p["Fs"], p["KT"], p["chi"], p["beta"], p["k"], p["m"], p["zeta_v"])


def _chirp(f0: float, f1: float, rate: float, amp: float, tail_s: float = 1.5):
    t_sw = abs(f1 - f0) / rate
    t = np.arange(int((t_sw + tail_s) * FS)) / FS
    sign = np.sign(f1 - f0)
    phase = 2 * np.pi * (f0 * t + 0.5 * sign * rate * t**2)
    env = np.where(t < t_sw, 1.0, 0.0)
    ramp = 0.05
    env *= np.clip(np.minimum(t / ramp, (t_sw - t) / ramp), 0, 1) ** 2
    return t, amp * env * np.sin(phase)


def campaign(folder: Path, *, seed: int = 1, families=("wide", "upper"), levels=LEVELS_LBF,
             noise: float = 0.01) -> pd.DataFrame:
    """Write the campaign (manifest.csv and one CSV per run, force in lbf, response in g); returns the manifest."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    rows, seq = [], 0
    for fam in families:
        spec = FAMILIES[fam]
        for level in levels:
            seq += 1
            t, force = _chirp(spec["f_start_hz"], spec["f_stop_hz"], spec["rate"], level)
            acc = np.zeros_like(force)
            for p in MODES.values():
                model = MinistackModel(m=p["m"], k=p["k"], zeta_v=p["zeta_v"],
                                       iwan=IwanParams(p["Fs"], p["KT"], p["chi"], p["beta"]))
                base_g = -force / (p["m"] * G)
                acc += simulate(model, base_g, FS).response_g - base_g
            acc += noise * np.std(acc) * rng.standard_normal(acc.size)
            force_n = force + noise * np.std(force) * rng.standard_normal(force.size)
            run_id = f"{fam}_{level:.2f}lbf"
            pd.DataFrame({"time_s": t, "force_lbf": force_n, "response_accel_g": acc}).to_csv(
                folder / f"{run_id}.csv", index=False, float_format="%.9g")
            rows.append(dict(run_id=run_id, assembly="beam", sequence=seq, level_lbf=level, direction="up",
                             f_start_hz=spec["f_start_hz"], f_stop_hz=spec["f_stop_hz"],
                             sweep_rate_hz_per_s=spec["rate"], sample_rate_hz=FS, file=f"{run_id}.csv"))
    manifest = pd.DataFrame(rows)
    manifest.to_csv(folder / "manifest.csv", index=False)
    return manifest
