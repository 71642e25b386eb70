"""Benchmark: generating one 12-run assembly (Table 3.1 series) at 25.6 kHz.

Run:  python tests/benchmarks/bench_synth.py
Prints the simulation time (the exact-Iwan integrator over all 12 sweeps) and the
whole generation time (DAQ chain and compressed CSV writing included).
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from jointcal.models import simulate
from jointcal.synth import generate, load_spec
from jointcal.synth.daq import controlled_sweep
from jointcal.synth.hidden import run_model
from jointcal.models import G


def main():
    spec = load_spec({"seed": 1, "sample_rate_hz": 25600.0, "measurement": {"oversample": 1},
                      "assemblies": {"first": {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004,
                                               "k": 6.12e5, "zeta_v": 0.0015}}})
    truth = dict(spec["assemblies"]["first"], m=spec["slug_weight_lbf"] / G)
    rng = np.random.default_rng(0)
    sweeps = []
    for item in spec["series"]:
        for _ in range(item["repeats"]):
            for d in item["directions"]:
                f0, f1 = (700.0, 2500.0) if d == "up" else (2500.0, 700.0)
                sweeps.append((item["level_g"], controlled_sweep(25600.0, f0, f1, 300.0, item["level_g"], rng=rng)[2]))
    model = run_model(truth, 1)
    simulate(model, sweeps[0][1][:1000], 25600.0)  # compile
    t0 = time.perf_counter()
    simulated = 0.0
    for _, a in sweeps:
        simulate(model, a, 25600.0)
        simulated += a.size / 25600.0
    sim = time.perf_counter() - t0
    print(f"12-run assembly at 25.6 kHz: {simulated:.0f} s of sweeps simulated in {sim:.2f} s "
          f"({simulated / sim:.0f} simulated s per wall s)")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        generate(spec, Path(tmp) / "c", Path(tmp) / "truth.json")
        print(f"whole generation (simulation + DAQ + csv.gz for 12 runs): {time.perf_counter() - t0:.2f} s")


if __name__ == "__main__":
    main()
