"""Test helpers (not jointcal code): the jointed beam as one driven mode, and a chirp of
its reference (a force or a voltage) with its manifest row and drive gain."""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.calibrate.space import PARAMS, ParamSpace
from jointcal.models import G, IwanParams, MinistackModel

# the jointed beam of tests/_support/rigs.py
BEAM = MinistackModel(m=1.0 / G, k=818.0, zeta_v=0.008, iwan=IwanParams(4.0, 204.0, -0.5, 0.1))
BEAM_JOINT = np.array([BEAM.iwan.Fs, BEAM.iwan.KT, BEAM.iwan.chi, BEAM.iwan.beta, BEAM.k, BEAM.zeta_v])  # as PARAMS
FS, F0, F1, RATE = 2048.0, 50.0, 150.0, 4.0  # the chirp starts and stops outside the fitted band (0.6-1.4 f_res)
GAINS = {"force": (complex(G), 0j, 2 * np.pi * 100.0),  # 1/m at the driving point, real, no slope
         "voltage": (complex(300.0, -150.0), complex(0.9, 0.6), 2 * np.pi * 100.0)}  # an amplifier's, sloped


def _run(ref: str, level: float, rate: float = RATE, f0: float = F0, f1: float = F1) -> tuple[pd.DataFrame, dict]:
    """A linear up-chirp of the reference at `level` (lbf or V) and `rate` (Hz/s) from f0 to f1 (Hz), and its
    manifest row with the drive gain."""
    t = np.arange(0.0, (f1 - f0) / rate + 2.0, 1 / FS)
    r = level * np.sin(2 * np.pi * (f0 * t + 0.5 * rate * t**2)) * np.minimum(1.0, t / 0.05)
    r[t > (f1 - f0) / rate] = 0.0
    col, lev = ("force_lbf", "level_lbf") if ref == "force" else ("drive_V", "level_V")
    rec = pd.DataFrame({"time_s": t, col: r, "response_accel_g": np.zeros_like(t)})
    row = {"run_id": "r1", "assembly": "beam", lev: level, "direction": "up", "f_start_hz": f0, "f_stop_hz": f1,
           "sweep_rate_hz_per_s": rate, "sample_rate_hz": FS, "sequence": 1, "drive_gain": GAINS[ref]}
    return rec, row


def beam_space() -> ParamSpace:
    """The modal kind's calibration space for the beam, bounded from data (`jointcal.calibrate.kind.data_bounds` at
    q 3e-3 and 3e-2 in, 99 and 97 Hz, zeta 1% and 1.5%)."""
    from jointcal.calibrate.kind import data_bounds

    b = data_bounds(np.array([3e-3, 3e-2]), np.array([99.0, 97.0]), np.array([0.01, 0.015]), BEAM.m)
    return ParamSpace(tuple(b[p][0] for p in PARAMS), tuple(b[p][1] for p in PARAMS))
