"""Benchmark: validating the example campaign (24 runs) with the optimum and 20 posterior draws.

Target: under 60 s on 2 cores. Prints the wall time, per-run times (optimum:
simulation + measure_run of both records; draws: segment simulations + lock-in), and
ratios against a baseline measured in the same run (one full-record simulate and one
measure_run of one record).

    python tests/benchmarks/bench_validate.py [RESULTS]   # RESULTS: a workflow results folder

With RESULTS holding calibration/<assembly>/ga_best.json and posterior/<assembly>/chain.npz
the calibrated models are used; otherwise the truth (without its hidden effect) and 20
draws jittered by 1% stand in (same cost).
"""
from __future__ import annotations

import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from jointcal.io import read_manifest, read_run
from jointcal.measure.modal import measure_run
from jointcal.models import simulate
from jointcal.validate import ValidateSettings, model_from_best, model_from_params, models_from_samples, validate_runs
from jointcal.validate.runs import clean_base

REPO = Path(__file__).parents[2]
KEYS = ("Fs", "KT", "chi", "beta", "k", "zeta_v")


def models_for(asm: str, results: Path | None, n_draws: int, rng: np.random.Generator):
    best_p = results / "calibration" / asm / "ga_best.json" if results else None
    chain_p = results / "posterior" / asm / "chain.npz" if results else None
    if best_p is not None and best_p.is_file() and chain_p.is_file():
        best = json.loads(best_p.read_text())
        with np.load(chain_p) as z:
            draws = models_from_samples(z["samples"], best["m"], n_draws, rng)
        return model_from_best(best), draws, "calibrated"
    truth = json.loads((REPO / "tests" / "example_campaign" / "truth.json").read_text())["assemblies"][asm]
    draws = [model_from_params({k: truth[k] * (1 + 0.01 * rng.standard_normal()) if k != "chi" else truth[k]
                                for k in KEYS}, truth["m"]) for _ in range(n_draws)]
    return model_from_params(truth, truth["m"]), draws, "truth (no hidden effect) + 1% jitter"


def main() -> None:
    results = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    raw = REPO / "raw_data"
    man = read_manifest(raw / "manifest.csv")
    rows_all = man.to_dict("records")
    records_all = [read_run(raw / r["file"]) for r in rows_all]
    s = ValidateSettings()
    # baseline: one full-record simulation and one measure_run (after numba's first call)
    opt0, _, _ = models_for(rows_all[0]["assembly"], results, 0, np.random.default_rng(0))
    base = clean_base(records_all[0])
    simulate(opt0, base[:2000], rows_all[0]["sample_rate_hz"])
    t = time.perf_counter()
    simulate(opt0, base, rows_all[0]["sample_rate_hz"])
    t_sim = time.perf_counter() - t
    t = time.perf_counter()
    measure_run(records_all[0], rows_all[0])
    t_meas = time.perf_counter() - t
    print(f"baseline: one full-record simulate {t_sim:.3f} s, one measure_run {t_meas:.3f} s")
    t0 = time.perf_counter()
    out = {}
    with ProcessPoolExecutor(max_workers=2) as ex:
        for asm in man["assembly"].unique():
            idx = [i for i, r in enumerate(rows_all) if r["assembly"] == asm]
            opt, draws, kind = models_for(asm, results, s.n_draws, np.random.default_rng(s.seed))
            v = validate_runs(lambda r: opt, [records_all[i] for i in idx], [rows_all[i] for i in idx], settings=s,
                              draws=draws, executor=ex)
            out[asm] = (v, kind)
    wall = time.perf_counter() - t0
    n_runs = sum(len(v.metrics) for v, _ in out.values())
    for asm, (v, kind) in out.items():
        m = v.metrics
        print(f"{asm} ({kind}): E = {v.error['E']:.2f}; per run: optimum simulate + 2 x measure_run "
              f"{m['sim_s'].mean():.2f} s, {int(m['n_draws'].iloc[0])} draws {m['draws_s'].mean():.2f} s "
              f"({m['draws_s'].mean() / m['n_draws'].iloc[0] * 1e3:.0f} ms per draw)")
    serial = n_runs * ((1 + s.n_draws) * (t_sim + t_meas) + t_meas)
    print(f"validated {n_runs} runs with the optimum and {s.n_draws} draws in {wall:.1f} s wall on 2 workers "
          f"(target < 60 s); every model through the full chain (full-record simulate + measure_run), serial, "
          f"at the baseline times: {serial:.0f} s, ratio {serial / wall:.2f}x")


if __name__ == "__main__":
    main()
