"""Acceptance: a structure with two amplitude-dependent modes, each calibrated on its own.

Run:  python tests/benchmarks/accept_modes.py [OUT]

The force-driven virtual structure of `tests/_support/two_modes.py` (a 100 Hz and a 230 Hz mode, each with its own
Iwan joint, integrated apart by the exact simulator, 1% noise): a wide chirp over both modes and a slow sweep
over the upper one alone, at three force levels, in one assembly. The workflow runs with the default config
up to the posterior (`snakemake --cores 2 posterior`). Printed: the modes found and the runs that hold each,
each run's read-out against its mode's first-harmonic balance at the run's q_in, and each calibrated curve
(model_curves.csv) against the truth at the measured amplitudes. Acceptance: both modes calibrated, each
curve within 0.1% in frequency and 5% in damping of its truth; the upper mode read from either family on one
backbone.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).parents[2]
sys.path.insert(0, str(HERE))
from tests._support import two_modes as _two_modes  # noqa: E402
from tests._support.workflow import workflow_copy  # noqa: E402

TRUTH_OF = {"m99": "low", "m227": "high", "m226": "high"}


def main(out: Path) -> bool:
    camp = out / "campaign"
    _two_modes.campaign(camp)
    work = workflow_copy(out)
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", "posterior", "--config",
                          f"raw_data={camp}", f"results={out / 'results'}"], cwd=work, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode:
        print(res.stderr[-4000:])
        return False
    modal = pd.read_csv(out / "results" / "modal" / "modal_properties.csv")
    print(f"workflow to the posterior: {wall:.0f} s\n")
    ok = True
    for mode, g in modal.groupby("mode", sort=False):
        truth = TRUTH_OF.get(mode)
        if truth is None:
            print(f"mode {mode}: no truth (a mode the structure does not have)")
            ok = False
            continue
        f_t, z_t = _two_modes.truth(truth, g["q_in"].to_numpy())
        t = g.assign(f_err_pct=100 * (g["f_res_hz"] / f_t - 1), zeta_err_pct=100 * (g["zeta_res"] / z_t - 1))
        print(f"mode {mode} ({truth}): runs {', '.join(g['run_id'])}")
        print(t[["run_id", "q_in", "f_res_hz", "zeta_res", "f_err_pct", "zeta_err_pct", "f_res_method"]].to_string(
            index=False, float_format=lambda v: f"{v:.5g}"))
        curves = pd.read_csv(out / "results" / "calibration" / "beam" / mode / "model_curves.csv")
        q = np.sort(g["q_in"].to_numpy())
        f_c = np.interp(np.log(q), np.log(curves["q_in"]), curves["f_hz"])
        z_c = np.interp(np.log(q), np.log(curves["q_in"]), curves["zeta"])
        f_t, z_t = _two_modes.truth(truth, q)
        df, dz = np.abs(f_c / f_t - 1).max(), np.abs(z_c / z_t - 1).max()
        print(f"calibrated curve vs truth at the measured q: max |df| {100 * df:.4f}%, max |dzeta| {100 * dz:.2f}%\n")
        ok &= bool(df < 1e-3 and dz < 0.05)
    print("PASS" if ok else "FAIL")
    return ok


if __name__ == "__main__":
    if len(sys.argv) > 1:
        sys.exit(0 if main(Path(sys.argv[1])) else 1)
    with tempfile.TemporaryDirectory() as d:
        sys.exit(0 if main(Path(d)) else 1)
