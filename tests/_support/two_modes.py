"""Test helpers (not jointcal code): virtual force- and voltage-driven campaigns of a jointed structure
with two amplitude-dependent modes, and each mode's truth.

The structure in modal coordinates (uncoupled modal Iwan joints, the modal-Iwan model of jointed
structures): two modes of unit modal mass at the driving point, each a spring k in parallel with its own
Iwan joint and a dashpot, driven by the same measured force F(t): m x_i'' + c_i x_i' + k_i x_i + F_iwan,i = F.
Each mode is integrated apart by the exact Iwan simulator (`jointcal.models.simulate`, the force given as
the base acceleration -F/m of a fixed-base oscillator); the driving point's acceleration is x_1'' + x_2''.
The truth of a mode at an amplitude q is its first-harmonic balance (`jointcal.models.harmonic_balance`).
Both channels carry 1% white noise (of the channel's rms), and the force is a prescribed-amplitude chirp
with 50 ms raised-cosine ramps.

Voltage-driven (`campaign(..., ref="voltage")`): the same two modes at the driving point of the small
open-loop shaker of `tests/_support/rigs.py` (coil, back-EMF, armature on its suspension), the chirp now
the amplifier's voltage. The coil and the armature couple the modes, so the rig is integrated as one
5-state system with an exact Iwan joint on each mode (`jointcal.synth.shaker.simulate_rig`, a jointed
`StructureMode`). What response / voltage shows of a mode is the coupled rig's pole, the shaker's
armature mass and electrical damping included; the truth of a mode at the amplitude q it has at the
driving point is that pole with each joint at its own coordinate's amplitude in the mode
(`jointcal.synth.rig_truth.rig_mode_pole`, the voltage truth of `tests/_support/rigs.py` with a second
joint).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.io import write_run
from jointcal.models import IwanParams, MinistackModel, harmonic_balance, simulate
from jointcal.synth.rig_truth import peak_amplitude, rig_mode_pole
from jointcal.synth.shaker import Shaker, StructureMode, simulate_rig
from jointcal.units import G

# a 100 Hz mode and a 230 Hz mode, both with about 2% softening over the levels' amplitudes
MODES = {"low": dict(k=818.0, Fs=4.0, KT=204.0, chi=-0.5, beta=0.1, zeta_v=0.008, m=1.0 / G),
         "high": dict(k=4327.0, Fs=4.0, KT=1079.0, chi=-0.5, beta=0.1, zeta_v=0.006, m=1.0 / G)}
FS = 1024.0
LEVELS_LBF = (0.04, 0.12, 0.32)
# the voltage-driven rig's levels: about the same amplitudes as LEVELS_LBF
LEVELS_V = (0.25, 0.75, 2.0)
SHAKER = {"armature_weight_lbf": 0.05, "suspension_hz": 15.0, "bl_lbf_per_A": 0.5, "coil_ohm": 2.0,
          "coil_mH": 0.3}  # tests/_support/rigs.py's small shaker
# two families of runs: a wide chirp over both modes, a slow sweep over the upper one alone
FAMILIES = {"wide": dict(f_start_hz=60.0, f_stop_hz=300.0, rate=24.0),
            "upper": dict(f_start_hz=195.0, f_stop_hz=265.0, rate=8.0)}


def truth(mode: str, q, ref: str = "force") -> tuple[np.ndarray, np.ndarray]:
    """(f Hz, zeta) of one mode at amplitude q (in): its first-harmonic balance (force), or the coupled
    voltage rig's pole of that mode at the amplitude q it has at the driving point (voltage)."""
    if ref == "voltage":
        model, shaker, second = rig()
        fz = [rig_mode_pole(model, shaker, second, float(v), 1 if mode == "low" else 2)[:2] for v in np.ravel(q)]
        f, z = np.array(fz).T
        return f.reshape(np.shape(q)), z.reshape(np.shape(q))
    p = MODES[mode]
    return harmonic_balance(q, p["Fs"], p["KT"], p["chi"], p["beta"], p["k"], p["m"], p["zeta_v"])


def _iwan(p: dict) -> IwanParams:
    return IwanParams(p["Fs"], p["KT"], p["chi"], p["beta"])


def rig() -> tuple[MinistackModel, Shaker, StructureMode]:
    """The voltage rig: the lower mode as the jointed structure, the upper as a jointed second mode."""
    lo, hi = MODES["low"], MODES["high"]
    model = MinistackModel(m=lo["m"], k=lo["k"], zeta_v=lo["zeta_v"], iwan=_iwan(lo))
    second = StructureMode(f_hz=float(np.sqrt((hi["k"] + hi["KT"]) / hi["m"]) / (2 * np.pi)), zeta=hi["zeta_v"],
                           weight_lbf=hi["m"] * G, iwan=_iwan(hi))
    return model, Shaker(**SHAKER), second


def _chirp(f0: float, f1: float, rate: float, amp: float, tail_s: float = 1.5):
    t_sw = abs(f1 - f0) / rate
    t = np.arange(int((t_sw + tail_s) * FS)) / FS
    sign = np.sign(f1 - f0)
    phase = 2 * np.pi * (f0 * t + 0.5 * sign * rate * t**2)
    env = np.where(t < t_sw, 1.0, 0.0)
    ramp = 0.05
    env *= np.clip(np.minimum(t / ramp, (t_sw - t) / ramp), 0, 1) ** 2
    return t, amp * env * np.sin(phase)


def _voltage_run(volts: np.ndarray) -> tuple[np.ndarray, dict]:
    """The voltage rig's driving-point acceleration (g) and each mode's reached amplitude at the driving
    point (in): the band-limited envelope peak of u = x + y near the mode's low-level pole."""
    model, shaker, second = rig()
    acc, _, x, y = simulate_rig(model, shaker, volts, FS, second=second, coordinates=True)
    q = {mode: peak_amplitude(x + y, FS, truth(mode, 1e-6, "voltage")[0]) for mode in MODES}
    return acc, q


def campaign(folder: Path, *, seed: int = 1, families=("wide", "upper"), levels=None, noise: float = 0.01,
             ref: str = "force") -> pd.DataFrame:
    """Write the campaign (manifest.csv and one CSV per run: force in lbf or voltage in V, response in g).

    Returns the manifest; for ref "voltage", with each mode's reached driving-point amplitude beside it
    (q_low_in, q_high_in; not written).
    """
    if ref not in ("force", "voltage"):
        raise ValueError(f"ref must be force or voltage, got {ref!r}")
    levels = (LEVELS_LBF if ref == "force" else LEVELS_V) if levels is None else levels
    unit = "lbf" if ref == "force" else "V"
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    rows, seq, reached = [], 0, []
    for fam in families:
        spec = FAMILIES[fam]
        for level in levels:
            seq += 1
            t, drive = _chirp(spec["f_start_hz"], spec["f_stop_hz"], spec["rate"], level)
            if ref == "force":
                acc = np.zeros_like(drive)
                for p in MODES.values():
                    model = MinistackModel(m=p["m"], k=p["k"], zeta_v=p["zeta_v"], iwan=_iwan(p))
                    base_g = -drive / (p["m"] * G)
                    acc += simulate(model, base_g, FS).response_g - base_g
            else:
                acc, q = _voltage_run(drive)
                reached.append({f"q_{mode}_in": v for mode, v in q.items()})
            acc += noise * np.std(acc) * rng.standard_normal(acc.size)
            drive_n = drive + noise * np.std(drive) * rng.standard_normal(drive.size)
            run_id = f"{fam}_{level:.2f}{unit}"
            write_run(folder / f"{run_id}.csv", t, drive_n, acc, kind=ref)
            rows.append({"run_id": run_id, "assembly": "beam", "sequence": seq, f"level_{unit}": level,
                         "direction": "up", "f_start_hz": spec["f_start_hz"], "f_stop_hz": spec["f_stop_hz"],
                         "sweep_rate_hz_per_s": spec["rate"], "sample_rate_hz": FS, "file": f"{run_id}.csv"})
    manifest = pd.DataFrame(rows)
    manifest.to_csv(folder / "manifest.csv", index=False)
    return manifest.join(pd.DataFrame(reached)) if reached else manifest
