"""Posterior stage: coordinates, likelihood, the 50-tau emcee run, resumption, summaries and coverage."""
from __future__ import annotations

import json
import multiprocessing
import pickle

import numpy as np
import pandas as pd
import pytest
import yaml
from tests._support.campaign import REPO
from tests._support.modal_tables import TABLE_3_2, modal_tables, write_tables

from jointcal.calibrate import PARAMS, CalibrateSettings, CalibrationInputError, run_calibration, select_modal
from jointcal.models import harmonic_balance
from jointcal.posterior import (
    LogPosterior, PosteriorSettings, constraints_text, log_det_dy_dx, projected_steps, run_chain, run_posterior,
    summarize, x_to_y, y_to_x,
)

CAL = CalibrateSettings()
FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])


def _lp(seed=1):
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=seed)
    return LogPosterior(select_modal(modal, "first", scatter=scatter), CAL.space, CAL.m)


# ---------------------------------------------------------------- coordinates and likelihood

def test_sampler_coordinates_round_trip_with_the_stated_jacobian():
    rng = np.random.default_rng(0)
    x = np.column_stack([rng.uniform(0, 4, 20), rng.uniform(4, 8, 20), rng.uniform(-0.95, 0, 20),
                         rng.uniform(-4, 0.7, 20), rng.uniform(4, 8, 20), rng.uniform(-4, -1, 20)])
    y = x_to_y(x, 1e-4)
    np.testing.assert_allclose(y_to_x(y, 1e-4), x, atol=1e-10)
    h = 1e-6
    for xi in x[:5]:
        J = np.array([(x_to_y(xi + h * e, 1e-4) - x_to_y(xi - h * e, 1e-4)) / (2 * h) for e in np.eye(6)]).T
        assert np.log(abs(np.linalg.det(J))) == pytest.approx(log_det_dy_dx(x_to_y(xi, 1e-4)), abs=1e-6)


def test_log_posterior_is_vectorised_and_minus_inf_outside_the_prior():
    lp = _lp()
    x_truth = np.r_[CAL.space.unit_to_x(CAL.space.to_unit(FIRST)), np.log10([3e-4, 0.012])]
    rng = np.random.default_rng(1)
    x = x_truth + 0.01 * rng.standard_normal((10, 8))
    x[3, 0] = 4.5  # Fs above its bound (1e4 lbf)
    x[4, 6] = np.log10(lp.data.rel_noise[0]) - 0.1  # sigma_f below the repeat-scatter floor
    y = lp.to_y(x)
    got = lp(y)
    assert np.isneginf(got[3]) and np.isneginf(got[4])
    assert np.all(np.isfinite(np.delete(got, [3, 4])))
    np.testing.assert_allclose(got, [lp(row[None])[0] for row in y], rtol=1e-12)
    np.testing.assert_allclose(lp.to_x(y), x, atol=1e-10)


def test_settings_snippet_equals_the_python_defaults():
    keys = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    assert PosteriorSettings.from_config(keys["posterior"]) == PosteriorSettings()
    with pytest.raises(ValueError, match="n_walkers"):
        PosteriorSettings.from_config({"n_walkers": 10})


# ---------------------------------------------------------------- emcee in chunks

def _gauss(x):
    return -0.5 * np.sum((x / [1.0, 3.0]) ** 2, axis=1)


def test_chain_stops_after_50_tau_and_resumes_exactly():
    x0 = 0.01 * np.random.default_rng(0).standard_normal((16, 2))
    full = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500)
    assert full.converged and full.steps > 50 * full.tau.max() and full.steps < 20000
    saved = []
    part = run_chain(_gauss, x0, seed=3, max_steps=1000, chunk=500, on_chunk=lambda s: saved.append(pickle.dumps(s)))
    assert part.steps == 1000 and not part.converged
    resumed = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, resume=pickle.loads(saved[-1]))
    np.testing.assert_array_equal(resumed.chain, full.chain)  # the chain continues, bit for bit
    np.testing.assert_array_equal(resumed.tau_history, full.tau_history)
    other = run_chain(_gauss, x0, seed=4, max_steps=500, chunk=500)
    assert not np.array_equal(other.chain, full.chain[:500])


def test_chain_whose_tau_grows_stops_early_and_says_why(monkeypatch):
    import jointcal.posterior.sampler as sampler

    x0 = 0.01 * np.random.default_rng(0).standard_normal((16, 2))
    on = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5)
    off = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500)
    assert on.converged and on.stop_reason == "converged" and on.steps == off.steps  # a mixing chain runs on
    # walkers that do not mix: the running tau grows in proportion to the chain (8 steps per 64, as the example
    # campaign's first chunks), so the chain length in units of tau stays flat and 50 tau is never reached
    monkeypatch.setattr(sampler, "_tau", lambda chain, observe: np.full(chain.shape[-1], len(chain) / 8.0))
    saved = []
    res = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5,
                    on_chunk=lambda s: saved.append(pickle.dumps(s)))
    assert not res.converged and res.stop_reason == "projected" and res.projected_steps > 1e9  # flat: no end
    assert res.steps == 3000  # checks 5 and 6 (min_chunks, then once more), not the cap of 40 checks
    again = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5,
                      resume=pickle.loads(saved[-2]))  # an interrupted run stops where the whole one did
    np.testing.assert_array_equal(again.chain, res.chain)
    capped = run_chain(_gauss, x0, seed=3, max_steps=4000, chunk=500)  # early stop off: runs to the cap
    assert capped.steps == 4000 and capped.stop_reason == "max_steps"
    # projections: tau settled at 100 steps -> 50 tau = 5000 steps; r = N/tau growing slowly -> far beyond
    assert projected_steps([[1000, 100.0], [2000, 100.0], [3000, 100.0]]) == pytest.approx(5000)
    r1, r3 = 4000 / 495.0, 6000 / 643.0  # equally spaced checks: the least-squares slope is (r3 - r1) / 2000
    assert projected_steps([[4000, 495.0], [5000, 576.0], [6000, 643.0]]) == pytest.approx(
        6000 + (50 - r3) / ((r3 - r1) / 2000), rel=1e-9)


def test_summary_flags_unconstrained_parameters_and_correlations():
    rng = np.random.default_rng(2)
    lower = np.array([0.0, 4.0, -0.95, -4.0, 4.0, -4.0, -4.0, -2.0])
    upper = np.array([4.0, 8.0, 0.0, 0.7, 8.0, -1.0, -1.3, -0.3])
    chain = np.empty((2000, 16, 8))
    chain[...] = (lower + upper) / 2 + 0.01 * rng.standard_normal(chain.shape)
    chain[..., 3] = rng.uniform(lower[3], upper[3], chain.shape[:2])  # beta: flat over its prior
    chain[..., 4] = chain[..., 1] + 0.001 * rng.standard_normal(chain.shape[:2])  # k follows KT
    s = summarize(chain, lower, upper, burn=100)
    assert list(s.columns) == ["param", "unit", "median", "q05", "q95", "tau", "n_eff", "prior_lo", "prior_hi",
                               "width_ratio", "constrained"]
    row = s.set_index("param")
    assert row.loc["beta", "width_ratio"] == pytest.approx(0.9, abs=0.02) and not row.loc["beta", "constrained"]
    assert row.loc["chi", "constrained"] and row.loc["KT", "median"] == pytest.approx(1e6, rel=0.01)
    text = constraints_text(s, chain, burn=100, q_max=1e-3)
    assert "beta is not constrained by the data" in text
    assert "as KT rises, k rises" in text


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


def test_residual_posterior_samples_a_known_gaussian_in_any_space_with_a_column_held():
    """Residuals linear in two parameters of a space that is not the joint's: the posterior is Gaussian,
    a ~ N(4, 0.5^2) and b ~ N(6, 1) (n E^2 = ((a - 4)/0.5)^2 + (b - 6)^2, T = 1), and the held column stays put."""
    from jointcal.calibrate import ParamSpace
    from jointcal.posterior import ResidualPosterior, draw_quantiles, sample_ball

    space = ParamSpace((0.0, 0.0, 1.0), (10.0, 10.0, 100.0), ("a", "b", "c"), (False, False, True))

    def residuals(theta):
        a, b = space.column(theta, "a"), space.column(theta, "b")
        return np.stack([(a - 4.0) / 0.5, b - 6.0], axis=-1) / np.sqrt(2.0)

    at = space.to_unit(space.vector({"a": 5.0, "b": 5.0, "c": 10.0}))
    lp = ResidualPosterior(space, residuals, 2, 1.0, at, space.free_mask(("c",)))
    assert lp.ndim == 2
    v = np.array([[0.4, 0.6], [0.5, 0.7]])
    np.testing.assert_allclose(lp(v), [0.0, -0.5 * (1.0 / 0.25 + 1.0)], atol=1e-12)  # -(1/2) sum of squares
    assert lp(np.array([[1.2, 0.5]]))[0] == -np.inf
    ch = sample_ball(lp, np.array([0.45, 0.55]), np.array([0.01, 0.01]), walkers=32, steps=3000, seed=3)
    q = draw_quantiles(lp.physical(ch.chain[500:].reshape(-1, 2)), space.names)
    assert q.at["c", "q05"] == pytest.approx(10.0) and q.at["c", "q95"] == pytest.approx(10.0)
    for p, mu, sd in (("a", 4.0, 0.5), ("b", 6.0, 1.0)):
        assert q.at[p, "median"] == pytest.approx(mu, abs=0.1 * sd)
        assert q.at[p, "q95"] - q.at[p, "q05"] == pytest.approx(2 * 1.6449 * sd, rel=0.08)


def test_integrated_time_is_emceess_estimator_and_the_ar1_closed_form():
    """The batched autocorrelation time equals emcee's estimator to rounding, and on long AR(1)
    chains the closed form tau = (1 + rho) / (1 - rho) within 10% (the estimator's error, a few %)."""
    import emcee

    from jointcal.posterior.sampler import integrated_time

    rng = np.random.default_rng(7)
    for n_t, rho in ((50, 0.5), (3000, 0.9), (20000, 0.8)):
        x = np.empty((n_t, 32, 3))
        x[0] = rng.normal(size=(32, 3))
        for t in range(1, n_t):
            x[t] = rho * x[t - 1] + np.sqrt(1 - rho**2) * rng.normal(size=(32, 3))
        x[..., 2] = 1e3 * np.exp(x[..., 2])  # scale and skew do not matter
        ours = integrated_time(x)
        np.testing.assert_allclose(ours, emcee.autocorr.integrated_time(x, tol=0), rtol=1e-12)
        if n_t >= 20000:  # long enough for the estimator's own error (a few %) to be small
            np.testing.assert_allclose(ours[:2], (1 + rho) / (1 - rho), rtol=0.1)
