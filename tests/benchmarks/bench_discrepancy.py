"""Acceptance and benchmark of the discrepancy stage on hidden-effect campaigns.

Each case: a campaign from the virtual lab (`jointcal.synth.generate`: exact-Iwan time
simulation, DAQ chain, one assembly, 1 g x2 up/down, 3 g and 10 g up/down) with joint
parameters, sample rate and sweep rate other than the example's, and one hidden effect
at a given strength; measured (`measure_run`), calibrated (GA on eq. 3.9), then
`jointcal.discrepancy.diagnose` with every library candidate (time-domain revalidation
included). Prints per case: named effect, confidence, E before and after, the fall, the
joint parameters' mean |log error| against the truth before and after, the stage's wall
time and the per-candidate times.

    python tests/benchmarks/bench_discrepancy.py [--only NAME] [--index 1,4] [--out FILE]

Strengths: cubic k3 = 2e11 lbf/in^3 moves the 10 g resonance by ~0.6% (3/4 k3 q^2 / (2 k) with
q ~ 3e-4 in, k ~ 1.2e6 lbf/in); quadratic c2 = 0.4 lbf s^2/in^2 adds 4 c2 q / (3 pi m) ~ 0.007 to
the 10 g damping (~20%); the rest span the ranges the library is meant for. Then two
effects at once (forward selection should name both) and what the library does not have
(a unilateral contact spring): a wrong library name given with high confidence fails them.
"""
import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.calibrate.space import PARAMS
from jointcal.discrepancy import DiscrepancySettings, diagnose
from jointcal.discrepancy.stage import valley_starts
from jointcal.io import read_manifest, read_run, write_csv_atomic
from jointcal.measure.modal import measure_run
from jointcal.measure.scatter import scatter
from jointcal.models import harmonic_balance
from jointcal.synth import generate

JOINTS = [dict(Fs=240.0, KT=1.3e6, chi=-0.55, beta=0.01, k=6.0e5, zeta_v=0.002),
          dict(Fs=380.0, KT=0.8e6, chi=-0.7, beta=0.004, k=9.0e5, zeta_v=0.0012)]
CASES = [
    ("none", {}), ("sensor_gain", {"gain": 0.85}), ("sensor_gain", {"gain": 1.2}),
    ("channel_delay", {"tau_s": 20e-6}), ("channel_delay", {"tau_s": 60e-6}),
    ("fixture_flexibility", {"f_can_hz": 3000.0}), ("fixture_flexibility", {"f_can_hz": 8000.0}),
    ("joint_settling", {"Fs_drift": 0.05, "KT_drift": 0.05}), ("joint_settling", {"Fs_drift": 0.15, "KT_drift": 0.1}),
    ("cubic_stiffening", {"k3": 2e11}), ("quadratic_damping", {"c2": 0.4}),
    # two effects at once: both named is right; a third name, or high confidence on one alone, is not
    ("sensor_gain", {"gain": 1.1, "also": {"name": "channel_delay", "params": {"tau_s": 4e-5}}}),
    ("fixture_flexibility", {"f_can_hz": 6000.0, "also": {"name": "quadratic_damping", "params": {"c2": 0.4}}}),
    # outside the library: a unilateral contact beyond a gap (engages above ~3 g) and from rest
    ("contact_spring", {"contact_k": 4e5, "gap_in": 8e-5}), ("contact_spring", {"contact_k": 2e5, "gap_in": 0.0}),
]


def diagnose_campaign(spec: dict, tmp: Path, assembly: str = "a", settings: DiscrepancySettings = DiscrepancySettings()):
    """Generate a virtual-lab campaign, measure it, calibrate `assembly` (GA) and diagnose it.

    Returns (diagnosis, modal table, ga_best, stage wall time in s)."""
    generate(spec, tmp / "c", tmp / "truth.json")
    man = read_manifest(tmp / "c" / "manifest.csv")
    rows, envs, records, props = [], {}, [], []
    for row in man.to_dict("records"):
        rec = read_run(tmp / "c" / row["file"])
        env, _, p = measure_run(rec, row)
        rows.append(row), records.append(rec), props.append(p)
        envs[row["run_id"]] = env
    table = pd.DataFrame(props)
    write_csv_atomic(table, tmp / "modal.csv")
    write_csv_atomic(scatter(table), tmp / "scatter.csv")
    run_calibration(tmp / "modal.csv", assembly, tmp / "cal", CalibrateSettings())
    best = json.loads((tmp / "cal" / "ga_best.json").read_text())
    starts = valley_starts(pd.read_csv(tmp / "cal" / "ga_history.csv"), best)
    mine = [i for i, r in enumerate(rows) if r["assembly"] == assembly]
    t0 = time.perf_counter()
    d = diagnose(assembly, envs, table, best, None, [records[i] for i in mine], [rows[i] for i in mine],
                 space=CalibrateSettings().space, settings=settings, joint_starts=starts)["diagnosis"]
    return d, table[table["assembly"] == assembly], best, time.perf_counter() - t0


def run_case(i, name, params, tmp: Path):
    joint = JOINTS[i % 2]
    spec = {"seed": 100 + i, "sample_rate_hz": (10000.0, 25600.0)[i % 2],
            "sweep": {"f_start_hz": 1500.0, "f_stop_hz": 2900.0, "rate_hz_per_s": (150.0, 500.0)[(i // 2) % 2]},
            "series": [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 2},
                       {"level_g": 3.0, "directions": ["up", "down"], "repeats": 1},
                       {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}],
            "assemblies": {"a": joint},
            "effect": {"name": name, "params": {k: v for k, v in params.items() if k != "also"},
                       **({"also": params["also"]} if "also" in params else {})}}
    d, table, best, wall = diagnose_campaign(spec, tmp)
    after = d["recalibrated"]["joint_parameters"]
    keys = [p for p in PARAMS if p != "beta"]
    e0 = np.mean([abs(np.log(best[p] / joint[p])) for p in keys])
    e1 = np.mean([abs(np.log(after[p]["value"] / joint[p])) for p in keys])
    per = ", ".join(f"{c['name']} {c['seconds']:.0f}s" for c in d["candidates"])
    floor = d["fast_model_floor"]["E"]
    each = " ".join(f"{p} {abs(np.log(best[p] / joint[p])):.2f}->{abs(np.log(after[p]['value'] / joint[p])):.2f}"
                    for p in keys)
    # what the envelopes identify: the joint's frequency and damping curves over the measured amplitudes
    q = np.geomspace(table["q_in"].min(), table["q_in"].max(), 40)
    m = float(best["m"])
    curve = lambda p: harmonic_balance(q, *(p[k] for k in ("Fs", "KT", "chi", "beta", "k")), m, p["zeta_v"])  # noqa: E731
    ft, zt = curve(joint)
    errs = []
    for p in (best, {k: v["value"] for k, v in after.items()}):
        f, z = curve(p)
        errs.append((np.max(np.abs(f / ft - 1)) * 100, np.max(np.abs(z / zt - 1)) * 100))
    kk = " ".join(f"{lab} {abs(np.log(v(best) / v(joint))):.2f}->{abs(np.log(v({k: x['value'] for k, x in after.items()}) / v(joint))):.2f}"
                  for lab, v in (("k+KT", lambda p: p["k"] + p["KT"]),))
    curves = (f"curves vs truth: f {errs[0][0]:.3f}%->{errs[1][0]:.3f}%, zeta {errs[0][1]:.1f}%->{errs[1][1]:.1f}%, {kk}")
    return (f"{name:20s} {json.dumps(params):40s} -> {d['effect']:20s} {d['confidence']:6s} "
            f"floor {floor if floor is None else round(floor, 2)} baseline S {d['baseline']['held_out_score']:.2f} "
            f"pairs tried {len(d['pairs_tried'])} "
            f"E {d['metric_before']:6.2f} -> {d['metric_after']:5.2f} ({(d['metric_after'] / d['metric_before'] - 1) * 100:+4.0f}%) "
            f"joint |log err| {e0:.2f} -> {e1:.2f} ({each}); {curves}; stage {wall:.0f} s ({per})")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", default=None)
    ap.add_argument("--index", default=None, help="comma-separated case numbers (0-based)")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lines = []
    for i, (name, params) in enumerate(CASES):
        if (a.only and name != a.only) or (a.index and str(i) not in a.index.split(",")):
            continue
        with tempfile.TemporaryDirectory() as d:
            line = run_case(i, name, params, Path(d))
        print(line, flush=True)
        lines.append(line)
        if a.out:
            Path(a.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
