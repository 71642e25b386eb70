"""End to end on campaigns from the virtual lab: raw records -> envelopes -> modal -> GA -> posterior.

The calibration tests in test_calibrate/test_posterior feed idealised modal tables; here
the tables come from the real estimators on default-generator campaigns (DAQ chain,
0.3% noise, 300 Hz/s), and the result is checked against the truth that made the data.
"""
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from _modal_helpers import modal_table
from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.io import write_csv_atomic
from jointcal.modal import scatter
from jointcal.models import harmonic_balance
from jointcal.posterior import PosteriorSettings, run_posterior
from jointcal.synth import generate

pytestmark = pytest.mark.slow

PARAMS = ("Fs", "KT", "chi", "beta", "k", "zeta_v")
TABLE_3_2 = {"first": {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015},
             "reassembly": {"Fs": 274.0, "KT": 0.90e6, "chi": -0.61, "beta": 0.025, "k": 8.56e5, "zeta_v": 0.0017}}


def _measure(tmp: Path, spec: dict):
    generate(spec, tmp / "campaign", tmp / "truth.json")
    table = modal_table(tmp / "campaign")
    write_csv_atomic(table, tmp / "modal_properties.csv")
    write_csv_atomic(scatter(table), tmp / "scatter.csv")
    return table, json.loads((tmp / "truth.json").read_text())


def _curve_errors(best: dict, truth: dict, q: np.ndarray):
    m = truth["m"]
    f_c, z_c = harmonic_balance(q, *(best[p] for p in PARAMS[:5]), m, best["zeta_v"])
    f_t, z_t = harmonic_balance(q, *(truth[p] for p in PARAMS[:5]), m, truth["zeta_v"])
    return np.max(np.abs(f_c / f_t - 1)), np.max(np.abs(z_c / z_t - 1))


def test_default_campaign_calibrates_to_the_truths_curves(tmp_path):
    table, truth = _measure(tmp_path, {"seed": 31})
    s = CalibrateSettings()
    for asm in ("first", "reassembly"):
        cal, _ = run_calibration(tmp_path / "modal_properties.csv", asm, tmp_path / asm, s)
        q = np.geomspace(table.loc[table.assembly == asm, "q_in"].min(), table.loc[table.assembly == asm, "q_in"].max(), 50)
        ef, ez = _curve_errors(cal.best, truth["assemblies"][asm], q)
        print(f"\n{asm}: objective {cal.best['objective']:.3g}; curves vs truth over the measured range: "
              f"frequency {ef * 100:.4f}%, damping {ez * 100:.2f}%")
        assert ef < 5e-4 and ez < 0.02


def test_posterior_intervals_cover_the_truth_across_campaigns(tmp_path):
    """Five campaigns drawn around Table 3.2: the 90% intervals of the constrained parameters."""
    rng = np.random.default_rng(2026)
    hits, pairs, rows = 0, 0, []
    for i in range(5):
        truth = {p: v * (1 + 0.15 * rng.uniform(-1, 1)) if p != "chi" else v + 0.08 * rng.uniform(-1, 1)
                 for p, v in TABLE_3_2["first"].items()}
        tmp = tmp_path / f"c{i}"
        _measure(tmp, {"seed": 100 + i, "assemblies": {"first": truth}})
        s = CalibrateSettings()
        run_calibration(tmp / "modal_properties.csv", "first", tmp / "cal", s)
        res, notes = run_posterior(tmp / "modal_properties.csv", tmp / "scatter.csv", tmp / "cal" / "ga_best.json",
                                   "first", tmp / "post", s, PosteriorSettings())
        summ = pd.read_csv(tmp / "post" / "summary.csv").set_index("param")
        for p in PARAMS:
            r = summ.loc[p]
            if not bool(r["constrained"]):
                continue
            pairs += 1
            inside = r["q05"] <= truth[p] <= r["q95"]
            hits += inside
            rows.append(f"c{i} {p}: truth {truth[p]:.4g} in [{r['q05']:.4g}, {r['q95']:.4g}]: {inside}")
    print("\n" + "\n".join(rows) + f"\ncoverage {hits}/{pairs}")
    assert pairs >= 15  # Fs, KT, chi, k, zeta_v are expected to be constrained in most campaigns
    assert hits >= 0.8 * pairs
