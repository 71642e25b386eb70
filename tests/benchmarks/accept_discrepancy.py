"""Acceptance matrices of the discrepancy stage: no false alarm, and two hidden effects named both.

Campaigns from the virtual lab (exact-Iwan time simulation, DAQ chain), measured,
calibrated (GA on eq. 3.9) and diagnosed with every library candidate
(`bench_discrepancy.diagnose_campaign`: the stage validates the calibrated model first,
as the workflow's validation stage does, then scores, decides, recalibrates and
revalidates in the time domain).

``--none``: no hidden effect, sample rates 10-25.6 kHz x sweep rates 100-600 Hz/s (the
corners and the example's 12.8 kHz at 400 Hz/s with the two Table 3.2 assemblies and
their 1-2-5-10 g series), three seeds each, and beyond that grid a lightly damped joint
swept at 800 Hz/s (eta up to about 1). Pass: 'none' every time. The table gives,
per campaign, the sweep's eta range, the fast model's floor (its envelope of the
calibrated model against the time simulation, E units), the calibrated model's
time-domain E, the baseline's held-out score, the verdict and the stage's time.

``--pairs``: fixture + quadratic damping, gain + delay, cubic + settling, three seeds
each (joints, sample and sweep rates alternate as in `bench_discrepancy.py`). Pass: both
named in at least 8 of 9, E after within 2x the repeat scatter (E <= 2), never a wrong
single name with confidence high, stage time under 4 minutes.

    python tests/benchmarks/accept_discrepancy.py --none|--pairs [--index 0,3] [--out FILE]
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_discrepancy import JOINTS, diagnose_campaign  # noqa: E402

SERIES = [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 2},
          {"level_g": 3.0, "directions": ["up", "down"], "repeats": 1},
          {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}]
SEEDS = (1, 2, 3)
CELLS = [(10000.0, 100.0), (10000.0, 600.0), (25600.0, 100.0), (25600.0, 600.0), (12800.0, 400.0)]
LIGHT = {"Fs": 1500.0, "KT": 1.0e6, "chi": -0.7, "beta": 0.004, "k": 7.0e5, "zeta_v": 0.0006}  # 1.1% at 1 g
LIGHT_RATE = 800.0  # with LIGHT: eta up to about 1
PAIRS = [
    ({"name": "fixture_flexibility", "params": {"f_can_hz": 6000.0}},
     {"name": "quadratic_damping", "params": {"c2": 0.4}}),
    ({"name": "sensor_gain", "params": {"gain": 1.1}}, {"name": "channel_delay", "params": {"tau_s": 4e-5}}),
    ({"name": "cubic_stiffening", "params": {"k3": 2e11}},
     {"name": "joint_settling", "params": {"Fs_drift": 0.15, "KT_drift": 0.1}}),
]


def none_cases():
    out = []
    for fs, rate in CELLS:
        for seed in SEEDS:
            example = (fs, rate) == (12800.0, 400.0)
            spec = {"seed": seed, "sample_rate_hz": fs, "sweep": {"rate_hz_per_s": rate}}
            if not example:
                spec["sweep"].update(f_start_hz=1500.0, f_stop_hz=2900.0)
                spec.update(series=SERIES, assemblies={"a": JOINTS[seed % 2]})
            for asm in (("first", "reassembly") if example else ("a",)):
                out.append((f"{fs / 1000:g} kHz {rate:g} Hz/s seed {seed} {asm}", spec, asm, None))
    for seed in SEEDS:  # beyond the grid: a lightly damped joint swept fast, eta up to about 1
        spec = {"seed": seed, "sample_rate_hz": 10000.0,
                "sweep": {"rate_hz_per_s": LIGHT_RATE, "f_start_hz": 1500.0, "f_stop_hz": 2900.0},
                "series": SERIES, "assemblies": {"a": LIGHT}}
        out.append((f"10 kHz {LIGHT_RATE:g} Hz/s light joint seed {seed} a", spec, "a", None))
    return out


def pair_cases():
    out = []
    for k, (one, two) in enumerate(PAIRS):
        for seed in SEEDS:
            i = 3 * k + seed
            spec = {"seed": 200 + i, "sample_rate_hz": (10000.0, 25600.0)[i % 2],
                    "sweep": {"f_start_hz": 1500.0, "f_stop_hz": 2900.0, "rate_hz_per_s": (150.0, 500.0)[(i // 2) % 2]},
                    "series": SERIES, "assemblies": {"a": JOINTS[i % 2]}, "effect": {**one, "also": two}}
            out.append((f"{one['name']} + {two['name']} seed {seed}", spec, "a", {one["name"], two["name"]}))
    return out


def row(label, spec, d, table, wall):
    eta = table["eta"].to_numpy(float)
    fl = d["fast_model_floor"]["E"]
    return (f"| {label} | {np.nanmin(eta):.2f}-{np.nanmax(eta):.2f} | {'-' if fl is None else f'{fl:.2f}'} | "
            f"{d['metric_before']:.2f} | {d['baseline']['held_out_score']:.2f} | {d['effect']} | {d['confidence']} | "
            f"{d['metric_after']:.2f} | {len(d['pairs_tried'])} | {wall:.0f} |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--none", action="store_true")
    ap.add_argument("--pairs", action="store_true")
    ap.add_argument("--index", default=None, help="comma-separated case numbers (0-based)")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    cases = (none_cases() if a.none else []) + (pair_cases() if a.pairs else [])
    lines = ["| campaign | eta | fast-model floor | E before | baseline S | verdict | confidence | E after | "
             "pairs tried | stage s |", "|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    tally = {"none": 0, "both": 0, "wrong_high": 0, "n": 0, "slow": 0}
    for i, (label, spec, asm, hidden) in enumerate(cases):
        if a.index and str(i) not in a.index.split(","):
            continue
        with tempfile.TemporaryDirectory() as tmp:
            d, table, _, wall = diagnose_campaign(spec, Path(tmp), asm)
        line = row(label, spec, d, table, wall)
        print(line, flush=True)
        lines.append(line)
        named = set(d["effects"])
        tally["n"] += 1
        tally["none"] += d["effect"] == "none"
        tally["both"] += bool(hidden) and named == hidden and d["metric_after"] <= 2.0
        tally["wrong_high"] += bool(hidden) and d["confidence"] == "high" and len(named) == 1 and not named <= hidden
        tally["slow"] += wall > (240 if d["pairs_tried"] else 120)
        if a.out:
            Path(a.out).write_text("\n".join(lines) + "\n")
    summary = (f"{tally['n']} campaigns: none {tally['none']}, both named with E after <= 2: {tally['both']}, "
               f"wrong single name with high confidence: {tally['wrong_high']}, over the time limit: {tally['slow']}")
    print(summary)
    if a.out:
        Path(a.out).write_text("\n".join(lines + ["", summary]) + "\n")


if __name__ == "__main__":
    main()
