"""validate.drive.drive_gain: the campaign's modal constant as the model is driven through it."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.validate.drive import drive_gain


def _table(level: str, a: np.ndarray, slope: np.ndarray, f: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({level: np.linspace(0.1, 1.0, a.size), "f_res_hz": f, "modal_constant_re": a.real,
                         "modal_constant_im": a.imag, "modal_slope_re": slope.real, "modal_slope_im": slope.imag})


def test_a_force_drives_through_the_magnitude_of_its_modal_constant_the_lag_is_the_channels():
    """Three force read-outs of a mode of modal mass m whose response channel lags the force by tau: each
    A = e^{-i w_r tau} / m at its own resonance. The model is driven through 1/m, real and flat."""
    m, tau = 0.00259, 4e-4
    f = np.array([99.4, 98.7, 97.6])
    a = np.exp(-2j * np.pi * f * tau) / m
    ac, da, wc = drive_gain(_table("level_lbf", a, np.zeros(3, complex), f))
    assert ac == pytest.approx(1 / m, rel=1e-12) and ac.imag == 0.0 and da == 0j
    assert wc == pytest.approx(2 * np.pi * 98.7)


def test_a_force_read_away_from_the_driving_point_keeps_its_residues_sign():
    """A response sensor away from the driving point reads the mode's real residue phi_s phi_d / m, which can be
    negative; a lagging channel turns it by -w tau. The model is driven through the residue with its sign, real and
    flat (its magnitude alone would turn the drive by 180 deg)."""
    r, tau = -0.4 / 0.00259, 4e-4
    f = np.array([99.4, 98.7, 97.6])
    ac, da, _ = drive_gain(_table("level_lbf", r * np.exp(-2j * np.pi * f * tau), np.zeros(3, complex), f))
    assert ac == pytest.approx(r, rel=1e-12) and ac.imag == 0.0 and da == 0j


def test_a_voltage_keeps_its_complex_constant_and_slope():
    """A voltage's A(w) is the coil's and the amplifier's, complex and sloped: moved to the median resonance
    along each run's slope, the medians of its parts."""
    f = np.array([99.0, 98.0, 97.0])
    slope = np.full(3, 0.5 - 2.0j)
    a = (300 - 40j) + slope * 2 * np.pi * (f - 98.0)
    ac, da, wc = drive_gain(_table("level_V", a, slope, f))
    assert ac == pytest.approx(300 - 40j) and da == pytest.approx(0.5 - 2.0j)


def test_a_voltage_models_channel_delay_counts_from_the_resonance_its_constant_was_read_at():
    """A voltage's A_c is read from the response channel at w_c, so it holds a delayed channel's phase there,
    -w_c tau. The jointed beam's model delaying its channel by tau, driven through that A_c, reads what the same model
    without the delay, driven through the undelayed A_c, reads delayed by tau: the delay counted once
    (`delay_reference` w_c). A force's drive is real (its phase left in the data) and a base's is itself: there the
    whole -w tau is the model's (`delay_reference` 0)."""
    from dataclasses import replace

    from jointcal.discrepancy.fit import candidate, model_at
    from jointcal.models import fractional_delay
    from jointcal.validate.drive import delay_reference, simulate_record
    from tests._support.beam_runs import BEAM, BEAM_JOINT, beam_space

    fs, tau, ac = 4000.0, 4e-4, 300.0 - 40.0j
    wc = 2 * np.pi * BEAM.f0_hz
    t = np.arange(0.0, 3.0, 1.0 / fs)
    f0, f1 = 0.7 * BEAM.f0_hz, 1.3 * BEAM.f0_hz
    record = pd.DataFrame({"time_s": t, "drive_V": 0.05 * np.sin(2 * np.pi * (f0 * t + (f1 - f0) * t**2 / 6.0))})
    row = {"run_id": "r1", "sample_rate_hz": fs, "level_V": 0.05, "drive_gain": (ac, 0j, wc)}
    delayed_row = {**row, "drive_gain": (ac * np.exp(-1j * wc * tau), 0j, wc)}
    model = model_at(candidate("baseline", beam_space(), BEAM.m), BEAM_JOINT, row)
    y0 = simulate_record(model, record, row)["response_accel_g"].to_numpy()
    y = simulate_record(replace(model, sensor_delay_s=tau), record, delayed_row)["response_accel_g"].to_numpy()
    inner = slice(int(0.2 * fs), int(2.8 * fs))  # away from the FFT's wrap of the drive's line-by-line gain
    err = np.max(np.abs(y - fractional_delay(y0, tau, fs))[inner]) / np.max(np.abs(y0))
    assert err < 2e-3
    assert delay_reference(delayed_row) == wc
    assert delay_reference({"level_lbf": 1.0, "drive_gain": (1 / BEAM.m, 0j, wc)}) == 0.0
    assert delay_reference({"level_g": 1.0}) == 0.0
