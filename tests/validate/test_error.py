"""The scale of E and of the chi-square without repeated runs: each read-out's own noise, never another bin's.

Known truths: frames of a smooth resonance curve plus Gaussian noise of a chosen standard
deviation (the runs' own noise must come back as that value); read-outs on a smooth
backbone plus noise of a chosen relative size (the posterior's noise scale must come back).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.validate.error import closeness, envelope_error, own_noise, repeat_scatter, scale_source

F0, ZETA = 100.0, 0.01


def _frames(rng, sigma_db, sigma_deg, f0=F0, n=400, bias_db=0.0):
    f = np.linspace(0.8 * f0, 1.2 * f0, n)
    r = f / f0
    h = 1.0 / (1 - r**2 + 2j * ZETA * r)
    mag = 20 * np.log10(np.abs(h)) + sigma_db * rng.standard_normal(n)
    ph = np.degrees(np.angle(h)) + sigma_deg * rng.standard_normal(n)
    return pd.DataFrame(dict(f_hz=f, mag_meas_db=mag, phase_meas_deg=ph, in_band=True,
                             d_mag_db=bias_db + 0 * f, d_phase_deg=0 * f))


def _metrics(ids, levels, directions):
    return pd.DataFrame(dict(run_id=ids, level=levels, direction=directions, n_frames=400, f_res_meas_hz=F0,
                             zeta_meas=ZETA))


def test_without_repeats_each_bin_takes_the_runs_own_noise():
    rng = np.random.default_rng(3)
    frames = {f"r{i}": _frames(rng, 0.2, 1.0) for i in range(3)}
    scale = repeat_scatter(frames, _metrics(list(frames), [1.0, 2.0, 3.0], ["up"] * 3))
    assert (scale["source"] == "own noise").all()
    # a quadratic follows the curve over a few frames: the noise comes back within 15% in every bin
    assert np.allclose(scale["sigma_mag_db"], 0.2, rtol=0.15), scale
    assert np.allclose(scale["sigma_phase_deg"], 1.0, rtol=0.15), scale
    assert scale_source(scale) == "own noise"


def test_a_bin_without_repeats_never_takes_another_bins_scatter():
    """Two runs repeat each other far from resonance only (their common band): the bins near resonance
    keep the runs' own noise (0.02 dB), not the far bin's repeat scatter (1 dB, e.g. two sweep rates)."""
    rng = np.random.default_rng(4)
    a, b = _frames(rng, 0.02, 0.1), _frames(rng, 0.02, 0.1)
    far = (a["f_hz"] / F0 - 1) / ZETA < -3
    b.loc[far, "mag_meas_db"] += rng.standard_normal(far.sum())  # the far bin differs by 1 dB between the two
    b.loc[~far, "in_band"] = False  # the second run's band: far below resonance only
    scale = repeat_scatter({"a": a, "b": b}, _metrics(["a", "b"], [1.0, 1.0], ["up", "up"]))
    assert scale["source"].tolist() == ["own noise", "own noise", "repeats"]
    assert scale["sigma_mag_db"].iloc[0] < 0.06 and scale["sigma_mag_db"].iloc[2] > 0.5


def test_two_sweep_rates_at_one_level_are_not_repeats():
    """Two runs at one level and direction, swept at two rates whose curves differ near resonance (the faster
    one's peak 0.5% higher: its transient), 0.2 dB and 1 deg of noise: their scale is that noise (within
    15%), not their difference; the same two runs at one rate are repeats, and the difference shows."""
    rng = np.random.default_rng(7)
    slow, fast = _frames(rng, 0.2, 1.0, n=1200), _frames(rng, 0.2, 1.0, f0=1.005 * F0, n=1200)
    m = _metrics(["slow", "fast"], [1.0, 1.0], ["up", "up"])
    scale = repeat_scatter({"slow": slow, "fast": fast}, m.assign(sweep_rate_hz_per_s=[1.0, 4.0]))
    assert (scale["source"] == "own noise").all()
    assert np.allclose(scale["sigma_mag_db"], 0.2, rtol=0.15), scale
    assert np.allclose(scale["sigma_phase_deg"], 1.0, rtol=0.15), scale
    same = repeat_scatter({"slow": slow, "fast": fast}, m.assign(sweep_rate_hz_per_s=[1.0, 1.0]))
    assert (same["source"] == "repeats").all() and same["sigma_phase_deg"].iloc[0] > 3 * 1.0


def test_e_of_a_biased_model_grows_with_the_own_noise_scale():
    """A 0.3 dB bias against runs of 0.1 dB own noise: E_mag = 3, outside the runs' own noise."""
    rng = np.random.default_rng(5)
    frames = {f"r{i}": _frames(rng, 0.1, 0.5, bias_db=0.3) for i in range(2)}
    m = _metrics(list(frames), [1.0, 2.0], ["up", "up"])
    err = envelope_error(frames, m, repeat_scatter(frames, m))
    assert err["E_mag"] == pytest.approx(3.0, rel=0.2)
    assert "outside" in closeness(err["E"], scale_source(err["scale"]))


def test_own_noise_needs_frames():
    rng = np.random.default_rng(6)
    fr = _frames(rng, 0.1, 0.5, n=12)
    sigma, dof = own_noise({"a": fr}, _metrics(["a"], [1.0], ["up"]).assign(n_frames=12))  # < 10 a bin and side
    assert (dof == 0).all() and np.isnan(sigma).all()


def test_the_words_on_decays_read_through_the_force_compare_no_envelopes_in_time():
    """A decay read through the force with the shaker attached decays at the rig's rate in the record and at the
    structure's in the model: its metrics give no envelope difference (NaN), and the words say why instead of
    'nan dB'; a free decay's envelope difference is given in dB."""
    from jointcal.validate.error import describe_misfit

    row = dict(run_id="r", test="ringdown", n_frames=12, n_windows=12, f_rel_err_mean=1e-4, zeta_rel_err_mean=-0.005,
               q_first_meas_in=8e-3, decades=1.9, env_end_db=np.nan)
    err = {"E": 1.3, "E_f": 1.1, "E_zeta": 1.5, "scale": [{"source": "own noise"}]}
    forced = describe_misfit(pd.DataFrame([row]), err)
    assert "envelopes in time are not compared" in forced and "nan" not in forced.lower()
    free = describe_misfit(pd.DataFrame([{**row, "env_end_db": -0.4}]), err)
    assert "decay envelope ends 0.40 dB below the measured" in free
