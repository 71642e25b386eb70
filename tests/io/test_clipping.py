"""Clipping (jointcal.io._clipping): samples piled at an ADC's full scale found at 12.8 and
25.6 kHz, none on clean, quantised or noiseless records, and why a clipped run stays out of the fit."""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, read_manifest, read_run, validate_run
from jointcal.io._clipping import clip_levels, clipped_mask
from tests._support.campaign import REPO
from tests._support.lti import lsim
from tests._support.ingest import _one_sentence


def test_clip_levels_finds_both_limits():
    x = np.sin(np.linspace(0, 6 * np.pi, 600))
    x = np.clip(x, -0.9, 0.95)
    levels = clip_levels(x, 3)
    assert [v for v, _, _ in levels] == [0.95, -0.9]
    assert [n for _, n, _ in levels] == [np.count_nonzero(x == 0.95), np.count_nonzero(x == -0.9)]
    assert clip_levels(np.sin(np.arange(1000.0)), 3) == []


def test_clean_data_with_repeated_nonextreme_values_is_not_clipped(small_campaign):
    row = read_manifest(small_campaign / "manifest.csv").iloc[0]
    df = read_run(small_campaign / row["file"])
    df.loc[1000:1009, "response_accel_g"] = 0.0  # a dropout at zero is not clipping
    assert validate_run(df, row, "x.csv")["flags"] == []


def test_clipped_mask_marks_exactly_the_clipped_samples():
    from jointcal.io._clipping import clipped_mask

    x = np.sin(np.linspace(0, 20 * np.pi, 2000)) * 1.3
    y = np.clip(x, -1.0, 1.1)  # asymmetric limits
    mask = clipped_mask(y)
    np.testing.assert_array_equal(mask, (y == 1.1) | (y == -1.0))
    assert not clipped_mask(x).any()


# ------------------------------------------------------------------------ clipping


def _sdof_sweep(fs: float, *, level: float = 1.0, fn: float = 2200.0, zeta: float = 0.02, rate: float = 2000.0,
                band: tuple[float, float] = (1800.0, 2600.0), seed: int = 7):
    """A linear SDOF base-excited sweep (exact for piecewise-linear input: scipy.signal.lsim's recursion, tests._support.lti).

    Returns time (s), base (g), absolute response (g) with 0.3 % noise, and the response's
    peak at resonance (g). Units g, s, Hz.
    """
    rng = np.random.default_rng(seed)
    f0, f1 = band
    sweep_s = (f1 - f0) / rate
    t = np.arange(int(round((sweep_s + 0.02) * fs))) / fs
    tt = np.minimum(t, sweep_s)
    base = level * np.sin(2 * np.pi * (f0 * tt + 0.5 * rate * tt**2)) * (t < sweep_s)
    w = 2 * np.pi * fn
    sdof = signal.StateSpace([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [-1.0]], [[-w * w, -2 * zeta * w]], [[0.0]])
    resp = lsim(sdof, base, t)
    base = base + 0.003 * level * rng.standard_normal(t.size)
    resp = resp + 0.003 * np.std(resp) * rng.standard_normal(t.size)
    return t, base, resp, float(np.abs(resp).max())


def _adc(x: np.ndarray, full_scale: float, bits: int = 24) -> np.ndarray:
    """A DAQ's ADC: quantised to `bits`, clipped at +/- full_scale (unit of x), as jointcal.synth.daq."""
    lsb = 2.0 * full_scale / 2**bits
    return np.clip(np.round(x / lsb), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * lsb


def _row(fs: float, band=(1800.0, 2600.0), rate=2000.0) -> dict:
    return {"run_id": "r1", "assembly": "a", "sequence": 1, "level_g": 1.0, "direction": "up",
            "f_start_hz": band[0], "f_stop_hz": band[1], "sweep_rate_hz_per_s": rate, "sample_rate_hz": fs,
            "file": "r1.csv"}


def _longest_flat_top(x: np.ndarray) -> int:
    at = np.r_[0, (x == x.max()).astype(np.int8), 0]
    edges = np.diff(at)
    return int((np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)).max())


@pytest.mark.parametrize("fs", [12800.0, 25600.0])
@pytest.mark.parametrize("frac", [0.6, 0.8, 0.95])
def test_clipping_at_a_fraction_of_the_resonance_peak_is_flagged(fs, frac):
    t, base, resp, peak = _sdof_sweep(fs)
    clipped = _adc(resp, frac * peak)  # the response channel's input range is frac x its peak
    df = pd.DataFrame({"time_s": t, "base_accel_g": _adc(base, 4.0), "response_accel_g": clipped})
    if fs == 12800.0:  # flat tops of 1-2 samples: the old ">= 3 consecutive" rule missed these
        assert _longest_flat_top(clipped) <= 2
    with pytest.warns(CampaignWarning) as record:
        checks = validate_run(df, _row(fs), "lab/r1.csv", on_data_problem="flag")
    assert checks["flags"] == ["clipped:response_accel_g"]
    msg = str(record[0].message)
    _one_sentence(msg, "lab/r1.csv", "'response_accel_g' is clipped", f"at {frac * peak:.6g}",
                  "repeat the run with a wider input range or a lower level")
    # the envelopes leave out exactly the samples at the clipped extremes
    mask = clipped_mask(clipped)
    np.testing.assert_array_equal(mask, np.isclose(np.abs(clipped), np.abs(clipped).max(), rtol=0, atol=1e-6 * peak))
    with pytest.raises(CampaignError, match="is clipped"):
        validate_run(df, _row(fs), "lab/r1.csv")
    clean = df.assign(response_accel_g=_adc(resp, 2.0 * peak))  # same run, input range 2x the peak
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert validate_run(clean, _row(fs), "lab/r1.csv")["flags"] == []


@pytest.mark.parametrize("bits", [24, 16, 12])
def test_clean_quantised_sweeps_are_not_clipped(bits):
    """A noisy sweep's extreme sample is unique: no pile-up, whatever the ADC's resolution."""
    t, base, resp, peak = _sdof_sweep(12800.0, seed=bits)
    for x, fsc in ((base, 2.0), (resp, 1.5 * peak)):
        assert clip_levels(_adc(x, fsc, bits)) == []


def test_noiseless_synthetic_references_are_not_clipped():
    """A float chirp or tone at a rational frequency hits its crest exactly on many samples
    (sin rounds to 1 within 1e-8 rad): no pile-up against the samples just below or mid-range."""
    fs = 25600.0
    t = np.arange(int(0.5 * fs)) / fs
    for x in (17.79 * np.sin(2 * np.pi * (1600 * t + 0.5 * 1000 * t**2)),  # 5 samples exactly at the crest
              np.sin(2 * np.pi * 1600 * t), np.sin(2 * np.pi * 1000 * t)):  # every value repeats
        assert clip_levels(x) == [] and not clipped_mask(x).any()


def test_committed_campaigns_raise_no_flag():
    """No false positive on the example campaign (24-bit, noise, ripple) or the small one."""
    for campaign in (REPO / "raw_data", REPO / "tests" / "data" / "small_campaign"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            runs = ingest_campaign(campaign)
        assert (runs["flags"] == "").all()


def test_silent_dropout_is_not_clipping(small_campaign):
    df = read_run(small_campaign / "run01.csv.gz")
    df.loc[3000:3400, "response_accel_g"] = 0.0
    assert clip_levels(df["response_accel_g"].to_numpy()) == []


def test_clipped_runs_stay_out_of_the_fit_because_leaving_frames_out_does_not_save_the_damping():
    """Why `clipped` is in UNUSABLE_FLAGS: with the clipped frames left out, the resonance peak is
    missing and the damping of a linear SDOF (zeta 0.02) clipped at 60 % of its peak comes out far high."""
    from jointcal.measure.modal import measure_run

    t, base, resp, peak = _sdof_sweep(12800.0)
    zeta = {}
    for frac in (2.0, 0.6):
        df = pd.DataFrame({"time_s": t, "base_accel_g": _adc(base, 4.0), "response_accel_g": _adc(resp, frac * peak)})
        zeta[frac] = measure_run(df, _row(12800.0))[2]["zeta_phase_resonance"]
    assert zeta[0.6] > 1.5 * zeta[2.0]  # measured: +90 % vs +13 % (the clean run's sweep-rate bias)
