"""End to end on campaigns from the virtual lab: raw records -> envelopes -> modal -> GA -> posterior.

The calibration tests in calibrate/ and posterior/ feed idealised modal tables; here
the tables come from the real estimators on default-generator campaigns (DAQ chain,
0.3% noise, 300 Hz/s), and the result is checked against the truth that made the data.
The coverage of the posterior's intervals over five such campaigns (seven minutes) is an
acceptance script, tests/benchmarks/accept_pipeline_coverage.py; the CI suite keeps
posterior/test_stage.py's coverage test on idealised tables.
"""
import json
import multiprocessing
from pathlib import Path

import numpy as np
import pytest

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.io import write_csv_atomic
from jointcal.measure.scatter import scatter
from jointcal.models import harmonic_balance

pytestmark = pytest.mark.slow

PARAMS = ("Fs", "KT", "chi", "beta", "k", "zeta_v")


def _measure(tmp: Path, campaign: Path, table):
    write_csv_atomic(table, tmp / "modal_properties.csv")
    write_csv_atomic(scatter(table), tmp / "scatter.csv")
    return table, json.loads((campaign.parent / "truth.json").read_text())


def _curve_errors(best: dict, truth: dict, q: np.ndarray):
    m = truth["m"]
    f_c, z_c = harmonic_balance(q, *(best[p] for p in PARAMS[:5]), m, best["zeta_v"])
    f_t, z_t = harmonic_balance(q, *(truth[p] for p in PARAMS[:5]), m, truth["zeta_v"])
    return np.max(np.abs(f_c / f_t - 1)), np.max(np.abs(z_c / z_t - 1))


def _calibrate(args):
    modal_csv, asm, out = args
    return run_calibration(modal_csv, asm, out, CalibrateSettings())[0].best


def test_default_campaign_calibrates_to_the_truths_curves(tmp_path, default_campaign_dir, default_modal):
    """The session's default campaign (conftest.py; its modal table shared with measure/test_modal.py)."""
    table, truth = _measure(tmp_path, default_campaign_dir, default_modal)
    jobs = [(tmp_path / "modal_properties.csv", asm, tmp_path / asm) for asm in ("first", "reassembly")]
    with multiprocessing.get_context("fork").Pool(2) as pool:  # the two GA runs are independent
        bests = pool.map(_calibrate, jobs)
    for (_, asm, _), best in zip(jobs, bests):
        cal = type("Cal", (), {"best": best})
        q = np.geomspace(table.loc[table.assembly == asm, "q_in"].min(), table.loc[table.assembly == asm, "q_in"].max(), 50)
        ef, ez = _curve_errors(cal.best, truth["assemblies"][asm], q)
        print(f"\n{asm}: objective {cal.best['objective']:.3g}; curves vs truth over the measured range: "
              f"frequency {ef * 100:.4f}%, damping {ez * 100:.2f}%")
        assert ef < 5e-4 and ez < 0.02
