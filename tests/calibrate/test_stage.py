"""The calibration stage's files (jointcal.calibrate.stage): the same config and seed give
the same bytes, and a run resumed from its checkpoint ends with them."""
from __future__ import annotations

import json

import pandas as pd
import pytest

from jointcal.calibrate import PARAMS, CalibrateSettings, run_calibration
from tests._support.modal_tables import TABLE_3_2, write_tables


@pytest.mark.slow
def test_same_seed_same_bytes_and_checkpoint_resume(tmp_path):
    """(d) same config and seed -> byte-identical ga_best.json; a run cut short and resumed from
    its checkpoint file ends with the same bytes."""
    modal_csv, _ = write_tables(tmp_path, TABLE_3_2, seed=2)
    s = CalibrateSettings.from_config({"population": 60, "offspring": 60, "generations": 30, "seed": 11,
                                       "n_polish": 1})
    out = [tmp_path / f"run{i}" for i in range(3)]
    run_calibration(modal_csv, "reassembly", out[0], s)
    run_calibration(modal_csv, "reassembly", out[1], s)
    short = CalibrateSettings.from_config({"population": 60, "offspring": 60, "generations": 10, "seed": 11,
                                           "n_polish": 1})
    ckpt = tmp_path / "ckpt" / "reassembly.pkl"
    run_calibration(modal_csv, "reassembly", tmp_path / "short", short, checkpoint=ckpt)  # "interrupted" at 10
    _, notes = run_calibration(modal_csv, "reassembly", out[2], s, checkpoint=ckpt)
    assert any("resuming the GA after generation 10" in n for n in notes)
    files = ("ga_best.json", "ga_history.csv", "ga_logbook.csv", "model_curves.csv")
    for f in files:
        assert (out[0] / f).read_bytes() == (out[1] / f).read_bytes() == (out[2] / f).read_bytes(), f
    best = json.loads((out[0] / "ga_best.json").read_text())
    assert {"Fs", "KT", "chi", "beta", "k", "zeta_v", "objective", "seed", "generations", "model"} <= set(best)
    curves = pd.read_csv(out[0] / "model_curves.csv")
    assert list(curves.columns) == ["q_in", "f_hz", "zeta", "model"]
    assert set(curves["model"]) == {"harmonic_balance", "qsma"}
    assert curves["q_in"].min() == pytest.approx(best["q_min_in"] / 3) and curves["q_in"].max() == pytest.approx(
        best["q_max_in"] * 3)
    history = pd.read_csv(out[0] / "ga_history.csv")
    assert list(history.columns) == ["generation", "objective", *PARAMS]
    assert len(history) == best["n_evaluations"] and history["objective"].min() == pytest.approx(
        best["objective_ga"])
