"""The design stage (jointcal.design.stage): evaluate and run_design on a base-driven
campaign write the three files; a force-driven campaign gets words instead of a level."""
from __future__ import annotations

import json

import numpy as np

from jointcal.calibrate import CalibrateSettings
from jointcal.design import DesignSettings, run_design
from jointcal.design.evaluate import REPORTED
from jointcal.posterior.identified import identified_table
from tests._support.microslip import M, PARAMS, TRUTH, null_draws, readouts
from tests._support.modal_tables import modal_tables
from tests.design.test_candidates import _runs

SPACE = CalibrateSettings().space
NAMES = [*PARAMS, "sigma_f", "sigma_zeta"]


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
    pm = table.set_index("quantity").loc["phi_max"]
    assert not pm["identified"]  # the null draws leave macroslip to the bounds: no bound is quoted as a target
    assert "until it exceeds" not in rec["what_would_identify"] and "search bounds" in rec["what_would_identify"]
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


def test_the_words_past_macroslip_quote_a_target_amplitude_only_where_the_data_place_it():
    """phi_max left to the bounds: no target amplitude (the issue's 'raise until q_in exceeds 0.625 in' when 0.9 in
    had been measured); placed above the runs: its upper end; placed below the largest amplitude: no more level."""
    import pandas as pd

    from jointcal.design.stage import _past_macroslip

    free = _past_macroslip(pd.Series({"identified": False, "q05": 0.0187, "q95": 1.53}), 0.008, "force")
    above = _past_macroslip(pd.Series({"identified": True, "q05": 0.02, "q95": 0.05}), 0.008, "force")
    below = _past_macroslip(pd.Series({"identified": True, "q05": 0.3, "q95": 0.625}), 0.9, "voltage")
    assert "until it exceeds" not in free and "search bounds" in free and "power law" in free
    assert "until it exceeds 0.05 in" in above
    assert "until it exceeds" not in below and "already pass it" in below
