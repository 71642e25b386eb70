"""The posterior stage (jointcal.posterior.stage): coverage and curves across campaigns,
the same seed's same summary, an interrupted chain resumed, a calibration of another model refused."""
from __future__ import annotations

import json
import multiprocessing

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import PARAMS, CalibrateSettings, CalibrationInputError, run_calibration
from jointcal.models import harmonic_balance
from jointcal.posterior import PosteriorSettings, run_posterior
from tests._support.modal_tables import TABLE_3_2, write_tables

CAL = CalibrateSettings()


# ---------------------------------------------------------------- stage runs (slow)

def _campaign(i: int, tmp):
    """Truths drawn around Table 3.2 (alternately its two assemblies), seeded by i."""
    rng = np.random.default_rng(100 + i)
    base = TABLE_3_2["first" if i % 2 == 0 else "reassembly"]
    z = rng.standard_normal(6)
    truth = dict(Fs=base["Fs"] * np.exp(0.3 * z[0]), KT=base["KT"] * np.exp(0.1 * z[1]), chi=base["chi"] + 0.03 * z[2],
                 beta=base["beta"] * np.exp(0.5 * z[3]), k=base["k"] * np.exp(0.1 * z[4]),
                 zeta_v=base["zeta_v"] * np.exp(0.2 * z[5]))
    modal_csv, scatter_csv = write_tables(tmp, {"a": truth}, seed=200 + i)
    return truth, modal_csv, scatter_csv


def _calibrate_and_sample(args):
    i, tmp = args
    truth, modal_csv, scatter_csv = _campaign(i, tmp)
    run_calibration(modal_csv, "a", tmp / "cal", CAL)
    res, notes = run_posterior(modal_csv, scatter_csv, tmp / "cal" / "ga_best.json", "a", tmp / "post", CAL,
                               PosteriorSettings())
    return truth, res.converged, res.steps, float(res.tau.max())


@pytest.mark.slow
@pytest.mark.acceptance
def test_coverage_and_curves_across_campaigns(tmp_path):
    """(c) 90% intervals contain the truth for >= 80% of the (parameter, campaign) pairs the data
    constrain (posterior 90% width < half the prior width in the sampling space), over 5 campaigns
    with truths drawn around Table 3.2; (b) the posterior-median harmonic-balance curves match the
    truth's within 0.05% (frequency) and 2% (damping) over the measured amplitudes."""
    jobs = [(i, tmp_path / f"c{i}") for i in range(5)]
    with multiprocessing.get_context("fork").Pool(2) as pool:
        out = pool.map(_calibrate_and_sample, jobs)
    hits, pairs, report = 0, 0, []
    for (i, tmp), (truth, converged, steps, tau) in zip(jobs, out):
        assert converged and steps > 50 * tau, (i, steps, tau)
        s = pd.read_csv(tmp / "post" / "summary.csv").set_index("param")
        for p in PARAMS:
            if s.loc[p, "constrained"]:
                pairs += 1
                hits += bool(s.loc[p, "q05"] <= truth[p] <= s.loc[p, "q95"])
        band = pd.read_csv(tmp / "post" / "predictive.csv")
        modal = pd.read_csv(tmp / "modal" / "modal_properties.csv")
        band = band[(band["q_in"] >= modal["q_in"].min()) & (band["q_in"] <= modal["q_in"].max())]
        f_t, z_t = harmonic_balance(band["q_in"].to_numpy(), truth["Fs"], truth["KT"], truth["chi"], truth["beta"],
                                    truth["k"], CAL.m, truth["zeta_v"])
        df = np.max(np.abs(band["f_q50"] / f_t - 1))
        dz = np.max(np.abs(band["zeta_q50"] / z_t - 1))
        report.append((i, steps, round(tau), round(100 * df, 4), round(100 * dz, 3)))
        assert df < 0.05e-2 and dz < 0.02, report[-1]
        constraints = (tmp / "post" / "constraints.txt").read_text()
        assert "converged by the 50-tau rule" in constraints and "beta is not constrained" in constraints
    assert pairs >= 15, pairs
    print(f"coverage {hits}/{pairs}", report)
    assert hits / pairs >= 0.8, (hits, pairs, report)


@pytest.mark.slow
def test_same_seed_same_summary_and_an_interrupted_chain_resumes(tmp_path):
    """(d) same config and seed -> byte-identical summary.csv; (e) a chain cut at 1000 steps
    continues from its checkpoint to the same chain (and bytes) as an uninterrupted run."""
    modal_csv, scatter_csv = write_tables(tmp_path, {"first": TABLE_3_2["first"]}, seed=7)
    cal = CalibrateSettings.from_config({"population": 60, "offspring": 60, "generations": 30, "n_polish": 2})
    run_calibration(modal_csv, "first", tmp_path / "cal", cal)
    best = tmp_path / "cal" / "ga_best.json"
    ps = PosteriorSettings.from_config({"max_steps": 3000, "chunk": 1000})
    for name in ("a", "b"):
        run_posterior(modal_csv, scatter_csv, best, "first", tmp_path / name, cal, ps)
    assert (tmp_path / "a" / "summary.csv").read_bytes() == (tmp_path / "b" / "summary.csv").read_bytes()
    ckpt = tmp_path / "ckpt" / "first.npz"
    short = PosteriorSettings.from_config({"max_steps": 1000, "chunk": 1000})
    first, _ = run_posterior(modal_csv, scatter_csv, best, "first", tmp_path / "cut", cal, short, checkpoint=ckpt)
    assert first.steps == 1000
    again, notes = run_posterior(modal_csv, scatter_csv, best, "first", tmp_path / "c", cal, ps, checkpoint=ckpt)
    assert any("resuming the chain after 1000 steps" in n for n in notes)
    np.testing.assert_array_equal(again.chain[:1000], first.chain)
    with np.load(tmp_path / "a" / "chain.npz") as z:
        np.testing.assert_array_equal(again.chain, z["chain"])
    assert (tmp_path / "c" / "summary.csv").read_bytes() == (tmp_path / "a" / "summary.csv").read_bytes()
    text = (tmp_path / "c" / "constraints.txt").read_text()
    assert text.startswith("emcee: 32 walkers, 3000 steps") and "NOT converged" in text
    band = pd.read_csv(tmp_path / "a" / "predictive.csv")
    assert list(band.columns) == ["q_in", "f_q05", "f_q50", "f_q95", "zeta_q05", "zeta_q50", "zeta_q95"]
    assert np.all(band["f_q05"] <= band["f_q50"]) and np.all(band["f_q50"] <= band["f_q95"])
    # a calibration made with another model is refused, naming the file
    edited = json.loads(best.read_text())
    edited["model"] = "qsma"
    best.write_text(json.dumps(edited))
    with pytest.raises(CalibrationInputError, match=f"{best}: it was calibrated with model 'qsma'"):
        run_posterior(modal_csv, scatter_csv, best, "first", tmp_path / "d", cal, ps)
