"""Test helpers (not jointcal code): virtual force- and voltage-driven campaigns of a jointed beam
with a second mode, and their read-outs set beside the truth's backbone.

The structure: a 100 Hz, 1 lbf jointed beam (spring k in parallel with an Iwan joint, zeta_v 0.8%:
about 2% of softening and twice the damping between 1e-4 and 1e-2 in), a second, linear mode at 230 Hz
at the driving point, on a small open-loop shaker. The truth's curve at an amplitude q is the
structure's first-harmonic balance (force reference: response / force is the structure alone) or the
coupled rig's pole (voltage: response / voltage holds the shaker), both with the second mode's
flexibility; the amplitude reached is the jointed mode's band-limited envelope peak over the record.
"""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.io import read_manifest, read_run
from jointcal.measure.modal import measure_run
from jointcal.models import G
from jointcal.synth import generate
from jointcal.synth.campaign import _model
from jointcal.synth.rig_truth import rig_pole, steady_amplitude, structure_equivalent
from jointcal.synth.shaker import Shaker, StructureMode

JOINTED_BEAM = {"k": 818.0, "Fs": 4.0, "KT": 204.0, "chi": -0.5, "beta": 0.1, "zeta_v": 0.008, "weight_lbf": 1.0}
SMALL_SHAKER = {"armature_weight_lbf": 0.05, "suspension_hz": 15.0, "bl_lbf_per_A": 0.5, "coil_ohm": 2.0,
                "coil_mH": 0.3}
SECOND_MODE = {"f_hz": 230.0, "zeta": 0.01, "weight_lbf": 0.5}
Q_TARGETS = (1e-3, 3e-3, 8e-3)  # steady-state amplitudes at resonance of the three levels, in


def rig():
    """(model, shaker, second mode) of the jointed beam."""
    truth = {k: v for k, v in JOINTED_BEAM.items() if k != "weight_lbf"}
    truth["m"] = JOINTED_BEAM["weight_lbf"] / G
    return _model(truth, 1, "none", {}), Shaker(**{**Shaker().__dict__, **SMALL_SHAKER}), StructureMode(**SECOND_MODE)


def truth_curve(ref: str, q):
    """The truth's (f Hz, zeta) at amplitude q (in) for a reference kind."""
    model, sh, second = rig()
    return structure_equivalent(model, q) if ref == "force" else rig_pole(model, sh, q, second)


def levels_V() -> list[float]:
    """Amplifier voltages whose steady states at resonance reach Q_TARGETS (a new list of `_levels_V`'s)."""
    return list(_levels_V())


@functools.cache
def _levels_V() -> tuple[float, ...]:
    """`levels_V`, solved once per process: 3 x 50 bisection steps of `steady_amplitude` (each itself 60 steps of
    the rig's FRF over 4001 frequencies), about 4 s of CPU, and the same numbers for every caller."""
    model, sh, second = rig()
    out = []
    for q in Q_TARGETS:
        lo, hi = 1e-4, 1e3
        for _ in range(50):
            mid = np.sqrt(lo * hi)
            lo, hi = (mid, hi) if steady_amplitude(model, sh, mid, second) < q else (lo, mid)
        out.append(float(round(np.sqrt(lo * hi), 4)))
    return tuple(out)


def campaign(folder: Path, truth_json: Path, *, ref: str, eta: float, direction: str = "up", seed: int = 1,
             noise: float = 0.02, levels: list[float] | None = None) -> float:
    """Write a three-level campaign at sweep-rate parameter eta (at the middle level's truth); returns the rate.

    Slow sweeps (eta <= 2) cross +-30% of the mode; faster ones 30-260 Hz, the second mode included.
    """
    f, z = truth_curve(ref, Q_TARGETS[1])
    rate = eta * (f * z) ** 2
    lo, hi = (0.7 * f, 1.3 * f) if eta <= 2 else (30.0, 260.0)
    lo, hi = (lo, hi) if direction == "up" else (hi, lo)
    spec = {"seed": seed, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": noise},
            "sweep": {"f_start_hz": lo, "f_stop_hz": hi, "rate_hz_per_s": rate,
                      "ramp_s": min(0.05, 0.02 * abs(hi - lo) / rate), "tail_s": 1.5},
            "series": [{"level_V": v, "directions": [direction]} for v in (levels or levels_V())],
            "assemblies": {"beam": JOINTED_BEAM},
            "rig": {"reference": ref, "shaker": SMALL_SHAKER, "second_mode": SECOND_MODE}}
    generate(spec, folder, truth_json)
    return rate


def read_out(folder: Path, truth_json: Path, ref: str, **modal_kw) -> pd.DataFrame:
    """Each run's read-out beside the truth: relative errors of f and zeta against the truth's curve at
    the run's own q_in, and of q_in against the amplitude the jointed mode reached."""
    import json

    runs = {r["run_id"]: r for r in json.loads(truth_json.read_text())["runs"]}
    rows = []
    for _, row in read_manifest(folder / "manifest.csv").iterrows():
        row = row.to_dict()
        props = measure_run(read_run(folder / row["file"]), row, modal_kw=modal_kw)[2]
        f_t, z_t = truth_curve(ref, props["q_in"])
        q_t = runs[row["run_id"]]["q_peak_in" if ref == "force" else "q_rig_peak_in"]
        rows.append(dict(run_id=row["run_id"], ref=ref, direction=row["direction"], method=props["f_res_method"],
                         eta=props["eta"], q_in=props["q_in"], q_truth=q_t, f_hz=props["f_res_hz"],
                         zeta=props["zeta_res"], f_err=props["f_res_hz"] / f_t - 1, zeta_err=props["zeta_res"] / z_t - 1,
                         q_err=props["q_in"] / q_t - 1, q_peak_err=props["q_peak_in"] / q_t - 1,
                         flags=props["flags"]))
    return pd.DataFrame(rows)


def kinds_spec(ref: str, seed: int) -> tuple[dict, callable]:
    """A campaign of the three test kinds (issue 31) on the rig driven by `ref` ('force' or 'voltage'): slow up
    sweeps (eta 0.5) at the three levels, a ring-down cut off from a dwell at the top level's resonance, and five
    dwells about the middle level's (each with its ring-down); 0.1% noise. Returns the synth spec and the truth's
    curve q -> (f Hz, zeta) (`truth_curve`)."""
    levels = levels_V()
    f_top, z_top = truth_curve(ref, Q_TARGETS[2])
    f_mid, z_mid = truth_curve(ref, Q_TARGETS[1])
    rate = 0.5 * (f_mid * z_mid) ** 2
    spec = {"seed": seed, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": 1e-3},
            "sweep": {"f_start_hz": 0.7 * f_mid, "f_stop_hz": 1.3 * f_mid, "rate_hz_per_s": rate,
                      "ramp_s": min(0.05, 0.02 * 0.6 * f_mid / rate), "tail_s": 1.5},
            "series": [{"level_V": v, "directions": ["up"]} for v in levels]
            + [{"level_V": levels[2], "test": "ringdown", "dwell_hz": [round(f_top, 3)], "dwell_s": 1.5,
                "decay_s": 2.5},
               {"level_V": levels[1], "test": "dwell", "dwell_s": 1.5, "decay_s": 2.5,
                "dwell_hz": [round(f_mid * (1 + k * z_mid), 3) for k in (-1.0, -0.5, 0.0, 0.5, 1.0)]}],
            "assemblies": {"beam": JOINTED_BEAM},
            "rig": {"reference": ref, "shaker": SMALL_SHAKER, "second_mode": SECOND_MODE}}
    return spec, lambda q: tuple(np.array([truth_curve(ref, v) for v in np.atleast_1d(q)]).T)
