"""Validation stage: the model driven by the measured base, through the same chain; E and its scale.

Oracles: an analytic FRF for a linear model; the truth that generated a synthetic campaign
(E of the true model is the noise floor); a hidden effect that the calibrated model lacks.
"""
from __future__ import annotations

import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from tests._support.modal_helpers import modal_table

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.io import read_manifest, read_run, write_csv_atomic
from jointcal.measure.modal import measure_run
from jointcal.models import MinistackModel, simulate
from jointcal.units import G
from jointcal.synth import generate
from jointcal.synth.hidden import run_model
from jointcal.validate import (
    ValidateSettings, band_frames, compare_run, draw_transmissibility, model_from_best, simulate_record,
    validate_runs,
)

TRUTH = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}
M = 2.65 / G


def _sweep_record(fs=12800.0, f0=1500.0, f1=3000.0, rate=1000.0, level=1.0, seed=0):
    """A clean linear sweep record with cosine ramps (g), and its manifest row."""
    n = int((f1 - f0) / rate * fs)
    t = np.arange(n) / fs
    f = f0 + rate * t
    ramp = np.clip(np.minimum(t, t[-1] - t) / 0.02, 0, 1)
    base = level * np.sin(2 * np.pi * np.cumsum(f) / fs) * (0.5 - 0.5 * np.cos(np.pi * ramp))
    base += 1e-4 * np.random.default_rng(seed).standard_normal(n)
    row = dict(run_id="r1", assembly="a", sequence=1, level_g=level, direction="up", f_start_hz=f0, f_stop_hz=f1,
               sweep_rate_hz_per_s=rate, sample_rate_hz=fs)
    return pd.DataFrame({"time_s": t, "base_accel_g": base, "response_accel_g": base}), row


def test_model_from_best_viscous_conventions():
    best = dict(TRUTH, m=M, viscous="dashpot")
    assert model_from_best(best).zeta_v == TRUTH["zeta_v"]  # the dashpot convention IS MinistackModel's
    const = model_from_best({**best, "viscous": "constant"}, f_ref_hz=2200.0)
    # a dashpot's ratio at f is zeta_v f0 / f: at f_ref it must equal the constant ratio
    assert const.zeta_v * const.f0_hz / 2200.0 == pytest.approx(TRUTH["zeta_v"], rel=1e-12)
    with pytest.raises(ValueError, match="reference frequency"):
        model_from_best({**best, "viscous": "constant"})


def test_linear_model_envelope_matches_the_analytic_frf():
    """A linear model through simulate + measure_run equals H = (k + i w c)/(k - m w^2 + i w c).

    A sweep at rate r shows the steady state delayed by the group delay tau_g = -dphi/domega
    (docs/physics.md, section 6), so the envelope at drive frequency f is H(f - r tau_g(f)) to first order in
    eta = r/(f zeta)^2 (0.1 here); the second-order remainder measured 0.05 dB at the peak,
    0.25 deg. Sampled at 25.6 kHz: at 12.8 kHz the simulator's cubic-Hermite reading of the
    sampled input attenuates it by 0.1 dB at 2.7 kHz (4.7 samples per cycle), 30x less here.
    Hence 0.08 dB and 0.4 deg.
    """
    model = MinistackModel(m=M, k=1.4e6, zeta_v=0.03)
    rate = 500.0
    record, row = _sweep_record(fs=25600.0, f0=1600.0, f1=3000.0, rate=rate)
    sim = simulate_record(model, record, row)
    env, _, props = measure_run(sim, row)
    use = band_frames(env, props["f_res_hz"], (0.8, 1.2))
    f = env["f_drive_hz"].to_numpy()[use]
    T = ((env["resp_re"] + 1j * env["resp_im"]) / (env["ref_re"] + 1j * env["ref_im"])).to_numpy()[use]
    c = 2 * model.zeta_v * np.sqrt(model.k * M)

    def H(f):
        w = 2 * np.pi * f
        return (model.k + 1j * w * c) / (model.k - M * w**2 + 1j * w * c)

    df = 0.01
    tau_g = -(np.angle(H(f + df) / H(f - df))) / (2 * np.pi * 2 * df)
    H_sweep = H(f - rate * tau_g)
    assert np.max(np.abs(20 * np.log10(np.abs(T / H_sweep)))) < 0.08
    assert np.max(np.abs(np.degrees(np.angle(T / H_sweep)))) < 0.4


def test_same_model_gives_zero_error_and_draws_match_the_full_chain():
    """Measured = simulated record: zero error; the draws' cheap path equals measure_run's envelope."""
    model = run_model(dict(TRUTH, m=M), 1)
    record, row = _sweep_record(f0=1700.0, f1=2700.0)
    meas = simulate_record(model, record, row)
    env, meta, props = measure_run(meas, row)
    frames, metrics = compare_run(env, props, env, props)
    assert metrics["n_frames"] > 50 and metrics["mag_err_rms_db"] < 1e-12 and metrics["peak_ratio"] == pytest.approx(1, abs=1e-12)
    sel = band_frames(env, props["f_res_hz"], (0.8, 1.2))
    T = draw_transmissibility([model], meas, env, meta, sel)[0]
    T_full = ((env["resp_re"] + 1j * env["resp_im"]) / (env["ref_re"] + 1j * env["ref_im"])).to_numpy()[sel]
    # segment simulation from a tapered lead-in and a rebuilt drive phase: 0.02 dB, 0.1 deg
    assert np.max(np.abs(20 * np.log10(np.abs(T / T_full)))) < 0.02
    assert np.max(np.abs(np.degrees(np.angle(T / T_full)))) < 0.1


def test_settings_reject_bad_values():
    with pytest.raises(ValueError, match="validate.band"):
        ValidateSettings(band=(1.1, 1.2))
    with pytest.raises(ValueError, match="unknown key"):
        ValidateSettings.from_config({"n_draw": 3})


SERIES = [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 2},
          {"level_g": 5.0, "directions": ["up", "down"], "repeats": 1},
          {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}]


def _campaign(tmp: Path, effect: dict, measurement: dict | None = None) -> tuple[list, list, dict, dict]:
    spec = {"seed": 41, "series": SERIES, "assemblies": {"first": TRUTH}, "effect": effect,
            "sweep": {"f_start_hz": 1600.0, "f_stop_hz": 2600.0}, "measurement": measurement or {}}
    generate(spec, tmp / "campaign", tmp / "truth.json")
    table = modal_table(tmp / "campaign")
    write_csv_atomic(table, tmp / "modal_properties.csv")
    cal, _ = run_calibration(tmp / "modal_properties.csv", "first", tmp / "cal", CalibrateSettings())
    man = read_manifest(tmp / "campaign" / "manifest.csv")
    rows = man.to_dict("records")
    records = [read_run(tmp / "campaign" / r["file"]) for r in rows]
    return rows, records, cal.best, json.loads((tmp / "truth.json").read_text())


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
                           [None, noisy, noisy]))
        rows, records, best, truth = made[0]
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
