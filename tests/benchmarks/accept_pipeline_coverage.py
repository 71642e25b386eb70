"""Acceptance: posterior 90% intervals cover the truth on campaigns measured from raw records.

Five campaigns from the virtual lab with truths drawn around Table 3.2 (first assembly):
raw records -> envelopes -> modal table (the real estimators) -> GA -> emcee. Counts the
(parameter, campaign) pairs the data constrain whose 90% interval holds the truth; passes
when at least 15 pairs are constrained and >= 80% are covered. Two campaigns at a time.
(Moved out of the CI suite for time: ~7 min on 2 cores; tests/posterior/test_stage.py keeps a coverage
test on idealised modal tables.)

    python tests/benchmarks/accept_pipeline_coverage.py
"""
import multiprocessing
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from tests._support.modal_helpers import modal_table  # noqa: E402
from jointcal.calibrate import CalibrateSettings, run_calibration  # noqa: E402
from jointcal.io import write_csv_atomic  # noqa: E402
from jointcal.measure.scatter import scatter  # noqa: E402
from jointcal.posterior import PosteriorSettings, run_posterior  # noqa: E402
from jointcal.synth import generate  # noqa: E402

PARAMS = ("Fs", "KT", "chi", "beta", "k", "zeta_v")
FIRST = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}


def truths(n=5, seed=2026):
    rng = np.random.default_rng(seed)
    return [{p: v * (1 + 0.15 * rng.uniform(-1, 1)) if p != "chi" else v + 0.08 * rng.uniform(-1, 1)
             for p, v in FIRST.items()} for _ in range(n)]


def one(args):
    i, truth, tmp = args
    tmp = Path(tmp)
    generate({"seed": 100 + i, "assemblies": {"first": truth}}, tmp / "campaign", tmp / "truth.json")
    table = modal_table(tmp / "campaign")
    write_csv_atomic(table, tmp / "modal_properties.csv")
    write_csv_atomic(scatter(table), tmp / "scatter.csv")
    s = CalibrateSettings()
    run_calibration(tmp / "modal_properties.csv", "first", tmp / "cal", s)
    run_posterior(tmp / "modal_properties.csv", tmp / "scatter.csv", tmp / "cal" / "ga_best.json", "first",
                  tmp / "post", s, PosteriorSettings())
    return pd.read_csv(tmp / "post" / "summary.csv").set_index("param")


def main() -> int:
    ts = truths()
    with tempfile.TemporaryDirectory() as d:
        jobs = [(i, t, Path(d) / f"c{i}") for i, t in enumerate(ts)]
        with multiprocessing.get_context("fork").Pool(2) as pool:
            summaries = pool.map(one, jobs)
    hits = pairs = 0
    for i, (truth, summ) in enumerate(zip(ts, summaries)):
        for p in PARAMS:
            r = summ.loc[p]
            if not bool(r["constrained"]):
                continue
            pairs += 1
            inside = r["q05"] <= truth[p] <= r["q95"]
            hits += inside
            print(f"c{i} {p}: truth {truth[p]:.4g} in [{r['q05']:.4g}, {r['q95']:.4g}]: {inside}")
    ok = pairs >= 15 and hits >= 0.8 * pairs
    print(f"coverage {hits}/{pairs}: {'PASS' if ok else 'FAIL'} (needs >= 15 constrained pairs, >= 80% covered)")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
