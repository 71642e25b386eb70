"""Generate ``tests/data/small_campaign/``: a tiny valid campaign with a known answer.

A LINEAR base-excited single-degree-of-freedom oscillator (mass m = 2.65 lbf / g,
natural frequency 2200 Hz, damping ratio 0.02) is driven by a linear sine sweep of
base acceleration, 1500 -> 2900 Hz (or back) at 2000 Hz/s, sampled at 12800 Hz, with
a 50 ms free-decay tail after the sweep. The response is the absolute acceleration
(base + relative), computed exactly for a piecewise-linear input by
`scipy.signal.lsim`, plus a little Gaussian noise. Units: g, s, Hz.

Runs: ``run01``-``run04`` (levels 1 and 2 g, up and down, ``.csv.gz``) and
``run05`` (1 g up, a repeat stored as MATLAB ``.mat``). Malformed cases are made
inside the tests from this valid campaign, never here.

Usage: ``python tests/data/make_small_campaign.py [OUT_DIR]`` (deterministic: seed 20240611).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from jointcal.io import write_csv_atomic, write_run
from jointcal.units import G

MASS = 2.65 / G  # lbf s^2/in (k = MASS * OMEGA**2 is the linear stiffness, lbf/in)
FN_HZ, ZETA = 2200.0, 0.02
F_LOW, F_HIGH, RATE, FS = 1500.0, 2900.0, 2000.0, 12800.0  # Hz, Hz, Hz/s, Hz
TAIL_S, FADE_S = 0.05, 0.005  # free decay after the sweep; cosine fade of the drive (s)
NOISE = 0.005  # noise standard deviation as a fraction of the level (g/g)
SEED = 20240611
RUNS = [  # run_id, sequence, level_g, direction, file
    ("run01", 1, 1.0, "up", "run01.csv.gz"),
    ("run02", 2, 1.0, "down", "run02.csv.gz"),
    ("run03", 3, 2.0, "up", "run03.csv.gz"),
    ("run04", 4, 2.0, "down", "run04.csv.gz"),
    ("run05", 5, 1.0, "up", "run05.mat"),
]


def sweep_record(level_g: float, f_start: float, f_stop: float,
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), base acceleration (g) and response acceleration (g), each shape (n,)."""
    sweep_s = abs(f_stop - f_start) / RATE
    t = np.arange(int(round((sweep_s + TAIL_S) * FS))) / FS
    k = np.sign(f_stop - f_start) * RATE
    base = level_g * np.sin(2 * np.pi * (f_start * t + 0.5 * k * t**2))
    fade = np.clip((sweep_s - t) / FADE_S, 0.0, 1.0)
    base *= 0.5 - 0.5 * np.cos(np.pi * fade)
    w = 2 * np.pi * FN_HZ
    # relative motion z'' + 2 zeta w z' + w^2 z = -a_base; absolute accel = -w^2 z - 2 zeta w z'
    sys_ = signal.StateSpace([[0.0, 1.0], [-w * w, -2 * ZETA * w]], [[0.0], [-1.0]],
                             [[-w * w, -2 * ZETA * w]], [[0.0]])
    _, response, _ = signal.lsim(sys_, base, t)
    base = base + NOISE * level_g * rng.standard_normal(t.size)
    response = response + NOISE * level_g * rng.standard_normal(t.size)
    return t, base, response


def make(out_dir: Path) -> pd.DataFrame:
    """Write the campaign into `out_dir` and return its manifest."""
    rng = np.random.default_rng(SEED)
    rows = []
    for run_id, seq, level, direction, file in RUNS:
        f0, f1 = (F_LOW, F_HIGH) if direction == "up" else (F_HIGH, F_LOW)
        write_run(out_dir / file, *sweep_record(level, f0, f1, rng), kind="base")
        rows.append({"run_id": run_id, "assembly": "first", "sequence": seq, "level_g": level,
                     "direction": direction, "f_start_hz": f0, "f_stop_hz": f1,
                     "sweep_rate_hz_per_s": RATE, "sample_rate_hz": FS, "file": file})
    manifest = pd.DataFrame(rows)
    write_csv_atomic(manifest, out_dir / "manifest.csv")
    return manifest


if __name__ == "__main__":
    make(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("small_campaign"))
