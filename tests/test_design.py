"""The design stage (jointcal.design): candidates, the steady-state read-out against closed forms, the predicted
narrowing against draws along the microslip null manifold (tests/_microslip.py), the ranking rule, and a force-
driven campaign that gets words instead of a level."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from tests._support.microslip import M, PARAMS, TRUTH, null_draws, readouts
from tests._support.modal_tables import modal_tables

from jointcal.calibrate import CalibrateSettings
from jointcal.design import DesignSettings, candidates, level_series, narrowing, rank, readout, run_design
from jointcal.design.evaluate import REPORTED, evaluate
from jointcal.models import derived, harmonic_balance, resonance_amplitude
from jointcal.posterior.identified import fisher, identified_table, quantities, unit_jacobian

SPACE = CalibrateSettings().space
NAMES = [*PARAMS, "sigma_f", "sigma_zeta"]


def _runs(levels=(1.0, 1.0, 2.0, 5.0, 10.0), rate=300.0):
    return pd.DataFrame({"assembly": "first", "level_g": levels, "direction": ["up", "down"] * (len(levels) // 2)
                         + ["up"] * (len(levels) % 2), "f_start_hz": 700.0, "f_stop_hz": 2500.0,
                         "sweep_rate_hz_per_s": rate})


def test_level_series_is_the_round_series_between_the_campaign_and_the_limit():
    assert level_series(1.0, 100.0) == [1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 50, 70, 100]
    assert level_series(0.8, 45.0) == [0.8, 1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 45]


def test_candidates_cover_levels_rates_and_directions_with_their_duration():
    c = candidates(_runs(), DesignSettings(max_level_g=20.0, rate_factors=(0.5, 2.0)))
    assert len(c) == 9 * 2 * 2  # 1, 1.5, 2, 3, 5, 7, 10, 15, 20 g, two rates, two directions
    assert set(c["sweep_rate_hz_per_s"]) == {150.0, 600.0}
    np.testing.assert_allclose(c["duration_s"], 1800.0 / c["sweep_rate_hz_per_s"])
    assert not c["repeat"].any()  # the campaign ran at 300 Hz/s, no candidate rate
    c = candidates(_runs(), DesignSettings(max_level_g=20.0, rate_factors=(1.0,)))
    assert set(c.loc[c["repeat"], "level_g"]) == {1.0, 2.0, 5.0, 10.0}
    assert not c[(c["level_g"] == 10.0) & (c["direction"] == "down")]["repeat"].any()  # 10 g was run up only
    with pytest.raises(ValueError, match="design.levels must lie in"):
        DesignSettings(levels=(200.0,))


@pytest.mark.parametrize("level", [1.0, 10.0, 100.0])
@pytest.mark.parametrize("direction", ["up", "down"])
def test_readout_is_the_phase_resonance_energy_balance_and_says_when_macroslip_is_passed(level, direction):
    theta = np.array([[TRUTH[p] for p in PARAMS]])
    r = readout(theta, level, direction, m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    q, f, z = resonance_amplitude(level, *theta[0, :5], M, theta[0, 5])
    assert bool(r["reached"].iloc[0])
    assert r["q_in"].iloc[0] == pytest.approx(float(q), rel=1e-9)
    f_hb, z_hb = harmonic_balance(float(q), *theta[0, :5], M, theta[0, 5])
    assert r["f_hz"].iloc[0] == pytest.approx(float(f_hb), rel=1e-9) and r["zeta"].iloc[0] == pytest.approx(float(z_hb))
    # energy balance at quadrature: the base's work pi m a q equals the dissipation 2 pi m omega^2 zeta q^2
    assert 2 * (2 * np.pi * r["f_hz"].iloc[0]) ** 2 * r["zeta"].iloc[0] * q == pytest.approx(level * 386.089, rel=1e-6)
    phi_max = derived(*theta[0, :4])[0]  # eq. 3.7
    assert bool(r["macroslip"].iloc[0]) == bool(q > phi_max) == (level == 100.0)
    # the envelope's peak: at least the phase-resonance response |a_b - omega^2 Z| / g
    assert r["peak_g"].iloc[0] >= 0.98 * np.hypot(level, (2 * np.pi * f_hb) ** 2 * q / 386.089)


def _setup(q, f, z, S):
    table, info = identified_table(S, NAMES, SPACE, q, f, z, m=M)
    qs = {qt.name: qt for qt in quantities(q, m=M, space=SPACE)}
    u = SPACE.to_unit(S[:, :6])
    grads = np.stack([unit_jacobian(lambda t, qt=qs[n]: (np.log10(qt.fn(t)) if qt.log else qt.fn(t))[:, None],
                                    u, SPACE)[1][:, 0] for n in REPORTED], axis=1)
    t = table.set_index("quantity")
    width = [float(np.log10(t.loc[n, "q95"] / t.loc[n, "q05"]) if t.loc[n, "log"] else t.loc[n, "q95"] - t.loc[n, "q05"])
             for n in REPORTED]
    return info, grads, width, [bool(t.loc[n, "identified"]) for n in REPORTED], np.cov(u, rowvar=False)


def test_a_test_below_macroslip_narrows_nothing_the_data_leave_free():
    q, f, z = readouts()
    S = null_draws(q_max=q.max(), seed=1)
    info, grads, width, ident, cov = _setup(q, f, z, S)
    r = readout(S[:, :6], 5.0, "up", m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    assert not r["macroslip"].any()
    tab, summ = narrowing(S[:, :6], S[:, 6:], info, r, grads, REPORTED, width, ident, cov, SPACE, m=M,
                          targets=("Fs", "KT/k"))
    t = tab.set_index("quantity")
    for name in ("Fs", "KT", "k", "beta", "KT/k"):  # flat along the manifold: one more microslip read-out adds nothing
        assert t.loc[name, "ratio"] == pytest.approx(1.0, abs=1e-3) and t.loc[name, "share_identified"] == 0.0
    assert summ["share_targets"] == 0.0 and t.loc["K0", "ratio"] > 1.0  # it does refine what is identified


def test_a_test_past_macroslip_for_every_draw_identifies_the_slip_force():
    q, f, z = readouts()
    S = null_draws(q_max=q.max(), split=(0.0, 0.3), seed=2)  # macroslip onsets within a factor ~2
    info, grads, width, ident, cov = _setup(q, f, z, S)
    r = readout(S[:, :6], 100.0, "up", m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    assert r["macroslip"].mean() > 0.95
    tab, summ = narrowing(S[:, :6], S[:, 6:], info, r, grads, REPORTED, width, ident, cov, SPACE, m=M,
                          targets=("Fs", "KT/k"))
    t = tab.set_index("quantity")
    assert summ["share_targets"] > 0.9 and summ["eig_nats"] > 1.0
    assert t.loc["Fs", "ratio"] > 5.0 and t.loc["KT/k", "ratio"] > 5.0


def _table(rows):
    t = pd.DataFrame(rows, columns=["level_g", "direction", "sweep_rate_hz_per_s", "share_targets", "ratio_Fs"])
    t["duration_s"] = 1800.0 / t["sweep_rate_hz_per_s"]
    t["eig_nats"] = 1.0
    return t


def test_rank_takes_the_lowest_level_that_identifies_then_the_shortest_sweep_within_the_sampling_error():
    t = _table([(10, "up", 300, 0.05, 1.1), (50, "up", 300, 0.96, 8.0), (50, "up", 1200, 0.95, 7.5),
                (50, "down", 1200, 0.95, 7.5), (100, "up", 300, 0.99, 9.0), (50, "up", 2400, 0.90, 6.0)])
    r = rank(t, ["Fs"], 0.9, ["up", "down"], n_draws=200)
    # 0.95 lies within one binomial standard error (0.014 at 0.96 and 200 draws) of the level's best, 0.90 does not
    assert r.loc[0, ["level_g", "direction", "sweep_rate_hz_per_s"]].tolist() == [50, "up", 1200]
    assert r.loc[0, "identifies"] and r["rank"].tolist() == list(range(1, 7))
    assert r.iloc[-1]["level_g"] == 10  # the level that identifies at the smallest share ranks last
    none = rank(t.assign(share_targets=t["share_targets"] * 0.5), ["Fs"], 0.9, ["up", "down"], n_draws=200)
    assert none.loc[0, "level_g"] == 100 and not none["identifies"].any()  # none reaches 90%: the largest share


def test_force_driven_campaign_gets_words_instead_of_a_level(tmp_path):
    modal, scatter = modal_tables({"first": TRUTH}, seed=4)
    modal = modal.rename(columns={"level_g": "level_lbf"})
    scatter = scatter.rename(columns={"level_g": "level_lbf"})
    modal.to_csv(tmp_path / "modal.csv", index=False)
    scatter.to_csv(tmp_path / "scatter.csv", index=False)
    q, f, z = readouts()
    S = null_draws(q_max=q.max())
    table, _ = identified_table(S, NAMES, SPACE, q, f, z, m=M)
    table.to_csv(tmp_path / "identified.csv", index=False)
    np.savez(tmp_path / "chain.npz", samples=S, sample_names=np.array(NAMES))
    best = {**TRUTH, "model_kind": "modal", "excitation": "force", "per_unit_modal_mass": True, "m": 1.0,
            "bounds": CalibrateSettings().full_bounds, "model": "harmonic_balance", "viscous": "dashpot",
            "damping": "zeta_res"}
    (tmp_path / "ga_best.json").write_text(json.dumps(best))
    rec, ranked = run_design(tmp_path / "missing_runs.csv", tmp_path / "modal.csv", tmp_path / "scatter.csv",
                             tmp_path / "ga_best.json", tmp_path / "chain.npz", tmp_path / "identified.csv", "first",
                             tmp_path / "design", CalibrateSettings(), DesignSettings(), eta_max=0.5)
    assert rec["applicable"] is False and rec["recommended"] is None and ranked.empty
    assert "force-driven" in rec["reason"] and "no level in lbf is recommended" in rec["reason"]
    assert "phi_max" in rec["what_would_identify"]
    saved = json.loads((tmp_path / "design" / "next_test.json").read_text())
    assert saved["recommended"] is None and "No level recommended" in (tmp_path / "design" / "next_test.md").read_text()


def test_evaluate_and_run_design_on_a_base_driven_campaign_write_the_three_files(tmp_path):
    q, f, z = readouts()
    S = null_draws(n=200, q_max=q.max(), seed=5)
    runs = _runs()
    runs.to_csv(tmp_path / "runs.csv", index=False)
    modal, scatter = modal_tables({"first": TRUTH}, seed=5, levels=(1, 1, 2, 5, 10))
    modal.to_csv(tmp_path / "modal.csv", index=False)
    scatter.to_csv(tmp_path / "scatter.csv", index=False)
    table, _ = identified_table(S, NAMES, SPACE, q, f, z, m=M)
    table.to_csv(tmp_path / "identified.csv", index=False)
    np.savez(tmp_path / "chain.npz", samples=S, sample_names=np.array(NAMES))
    (tmp_path / "ga_best.json").write_text(json.dumps({**TRUTH, "model_kind": "ministack", "excitation": "base"}))
    settings = DesignSettings(draws=50, rate_factors=(1.0, 4.0), levels=(1.0, 10.0, 100.0))  # + the measured 2, 5 g
    rec, ranked = run_design(tmp_path / "runs.csv", tmp_path / "modal.csv", tmp_path / "scatter.csv",
                             tmp_path / "ga_best.json", tmp_path / "chain.npz", tmp_path / "identified.csv", "first",
                             tmp_path / "design", CalibrateSettings(), settings, eta_max=0.5)
    assert rec["recommended"]["level_g"] == 100.0 and rec["targets"] == ["Fs", "KT/k"]
    assert set(rec["predicted_width_ratio"]) == set(REPORTED) and rec["predicted_width_ratio"]["Fs"] > 1.0
    assert len(ranked) == 5 * 2 * 2 and (tmp_path / "design" / "next_test.csv").is_file()
    md = (tmp_path / "design" / "next_test.md").read_text()
    assert "Recommended: a 100 g base sweep" in md and "Criterion:" in md and "Rule:" in md
