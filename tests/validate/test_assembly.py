"""Validation of one assembly (jointcal.validate.assembly): settings checked, and E of the
calibrated model at the noise floor, growing with a hidden effect the model lacks.

Oracles: the truth that generated a synthetic campaign (E of the true model is the noise floor); a hidden effect
that the calibrated model lacks."""
from __future__ import annotations

import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.io import read_manifest, read_run, write_csv_atomic
from jointcal.synth import generate
from jointcal.synth.hidden import run_model
from jointcal.validate import ValidateSettings, model_from_best, validate_runs
from tests._support.modal_helpers import modal_table

TRUTH = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}


def test_settings_reject_bad_values():
    with pytest.raises(ValueError, match="validate.band"):
        ValidateSettings(band=(1.1, 1.2))
    with pytest.raises(ValueError, match="unknown key"):
        ValidateSettings.from_config({"n_draw": 3})


SERIES = [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 2},
          {"level_g": 5.0, "directions": ["up", "down"], "repeats": 1},
          {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}]


def _campaign(tmp: Path, effect: dict, measurement: dict | None = None,
              calibrate: bool = True) -> tuple[list, list, dict | None, dict]:
    """A campaign of the truth with `effect` hidden, its records and (with `calibrate`) the GA optimum of its modal
    table; the campaign that only checks the simulation (the true model driven by its records) needs no optimum."""
    spec = {"seed": 41, "series": SERIES, "assemblies": {"first": TRUTH}, "effect": effect,
            "sweep": {"f_start_hz": 1600.0, "f_stop_hz": 2600.0}, "measurement": measurement or {}}
    generate(spec, tmp / "campaign", tmp / "truth.json")
    best = None
    if calibrate:
        table = modal_table(tmp / "campaign")
        write_csv_atomic(table, tmp / "modal_properties.csv")
        best = run_calibration(tmp / "modal_properties.csv", "first", tmp / "cal", CalibrateSettings())[0].best
    man = read_manifest(tmp / "campaign" / "manifest.csv")
    rows = man.to_dict("records")
    records = [read_run(tmp / "campaign" / r["file"]) for r in rows]
    return rows, records, best, json.loads((tmp / "truth.json").read_text())


@pytest.mark.slow
def test_E_of_the_calibrated_model_is_at_the_noise_floor_and_grows_with_a_hidden_effect(tmp_path):
    """E(calibrated) <= 1.5 E(true model) without an effect; >= 3x with sensor_gain 1.15.

    One assembly, 1 g x2 repeats up/down, 5 g and 10 g, band 1600-2600 Hz (CI time). The true
    model's E is the noise floor only where noise sets the scale: the campaigns carry 2% sensor
    noise (the repeat scatter then exceeds E's 0.05 dB / 0.3 deg floors near resonance). At the
    virtual lab's default 0.3% the scale is the floors, far above the noise: E(true) = 0.11 and
    E(calibrated) = 0.28 (the eq. 3.9 optimum misses f by 0.02% and zeta by 0.2%), both far
    inside the scatter; that campaign checks the simulation itself: the true model driven by the
    measured base records reproduces every run's measured resonance within 1e-4 and damping
    within 0.2% through the same chain (measured 4e-5 and 0.09%; with the input taken as cubic
    between samples, before the band-limited reconstruction, 1e-3 and 1.8%). Measured: 2% noise: E true 0.53, calibrated 0.63;
    sensor_gain 1.15: 16.
    """
    noisy = {"noise_fraction": 0.02}
    with ProcessPoolExecutor(max_workers=2) as ex:  # three independent campaigns, then their validations
        made = list(ex.map(_campaign, [tmp_path / "exact", tmp_path / "none", tmp_path / "gain"],
                           [{"name": "none"}, {"name": "none"}, {"name": "sensor_gain", "params": {"gain": 1.15}}],
                           [None, noisy, noisy], [False, True, True]))
        rows, records, _, truth = made[0]  # the true model only: no calibration of this campaign
        a = truth["assemblies"]["first"]
        v_exact = validate_runs([run_model(a, r["sequence"]) for r in rows], records, rows, executor=ex)
        rows, records, best, truth = made[1]
        e_true = validate_runs([run_model(a, r["sequence"]) for r in rows], records, rows, executor=ex).error["E"]
        e_cal = validate_runs(lambda r: model_from_best(best), records, rows, executor=ex).error["E"]
        rows, records, best_g, _ = made[2]
        v_gain = validate_runs(lambda r: model_from_best(best_g), records, rows, executor=ex)
    m = v_exact.metrics
    print(f"\nexact model at 0.3% noise: E {v_exact.error['E']:.2f}, max |f_res error| "
          f"{m['f_res_rel_err'].abs().max():.1e}, max |zeta error| {m['zeta_rel_err'].abs().max():.1e}\n"
          f"2% noise: E true model {e_true:.2f}, calibrated {e_cal:.2f}, calibrated on a sensor_gain 1.15 campaign "
          f"{v_gain.error['E']:.2f}\n{v_gain.words}")
    assert m["f_res_rel_err"].abs().max() < 1e-4 and m["zeta_rel_err"].abs().max() < 2e-3
    assert e_cal <= 1.5 * e_true
    assert v_gain.error["E"] >= 3 * e_cal
