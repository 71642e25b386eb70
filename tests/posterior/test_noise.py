"""The posterior's noise scale without repeats, its stops in words, and a chain that cannot identify.

Known truths: read-outs on a smooth backbone plus relative noise of a chosen size; runs of two modes
interleaved over the same amplitudes; a chain's convergence state and mode labels set by hand; draws
past macroslip that identify every parameter when the chain has settled (tests/posterior/test_identified.py).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import CalibrateSettings
from jointcal.calibrate.data import ModalData
from jointcal.posterior import LogPosterior
from jointcal.posterior.identified import identified_table, unsettled
from jointcal.posterior.identified import settled as settled_table
from jointcal.posterior.noise import data_problem, noise_scale, readout_noise
from tests._support.microslip import M, PARAMS, TRUTH, readouts

SPACE = CalibrateSettings().space
FLOORS = {"frequency": 1e-4, "damping": 0.01}


def _data(q, f, z, runs=None, noise=(np.nan, np.nan)):
    runs = tuple(runs or (f"r{i}" for i in range(len(q))))
    return ModalData("a", runs, np.asarray(q, float), np.asarray(q, float), np.asarray(f, float),
                     np.asarray(z, float), "zeta_res", noise, ())


def _backbone(n, sigma, seed=1):
    rng = np.random.default_rng(seed)
    q = np.geomspace(0.01, 1.0, n)
    f = 100 * (1 - 0.03 * q**0.6) * (1 + sigma[0] * rng.standard_normal(n))
    z = 0.005 * (1 + 2 * q**0.8) * (1 + sigma[1] * rng.standard_normal(n))
    return q, f, z


def test_read_outs_own_scatter_recovers_the_noise_of_a_smooth_backbone():
    q, f, z = _backbone(60, (0.002, 0.03))
    s_f, s_z, dof = readout_noise(q, f, z)
    assert dof == 57
    assert s_f == pytest.approx(0.002, rel=0.2) and s_z == pytest.approx(0.03, rel=0.2)
    assert np.isnan(readout_noise(q[:4], f[:4], z[:4])[0])  # four amplitudes leave one dof: no estimate


def test_without_repeats_the_noise_scale_is_the_read_outs_own_not_the_floor():
    q, f, z = _backbone(8, (0.003, 0.05), seed=2)
    none = pd.DataFrame(dict(assembly=["a", "a"], quantity=["f_res_hz", "zeta_res"], source="pooled", n=0,
                             rel_std=np.nan))
    data, sources, notes = noise_scale(_data(q, f, z, noise=(1e-4, 0.01)), none, FLOORS)
    assert sources == ("own", "own") and len(notes) == 2
    own = readout_noise(q, f, z)
    assert data.rel_noise == pytest.approx(own[:2]) and data.rel_noise[0] > 1e-3  # not the 1e-4 floor
    repeats = none.assign(n=[5, 5], rel_std=[0.004, 0.07])
    data, sources, _ = noise_scale(_data(q, f, z, noise=(0.004, 0.07)), repeats, FLOORS)
    assert sources == ("repeats", "repeats") and data.rel_noise == (0.004, 0.07)


def test_two_modes_in_one_assembly_name_the_runs_and_the_config_fix():
    """The held-out beam: 70-110 Hz runs read at the 95 Hz mode, 0.5-110 Hz runs at 18.6 Hz, same levels; the
    18.6 Hz mode's displacement is (95/18.6)^2 = 26x larger, so their amplitudes do not overlap."""
    level = np.repeat([0.05, 0.1, 0.2, 0.3], 2)
    q = level * np.tile([1.0, 26.0], 4)
    f = np.tile([95.0, 18.6], 4) * (1 - 0.01 * level)
    data = replace(_data(q, f, np.full(8, 0.02), runs=[f"{r}_{v}" for v in range(4) for r in ("slow", "fast")]),
                   level=level)
    text = dict(data_problem(data, noise=(0.9, 0.7), noise_max=(0.05, 0.5)))
    assert "two_modes" in text and "noise" in text
    assert "mode_hz: 94" in text["two_modes"] and "slow_0" in text["two_modes"] and "fast_0" in text["two_modes"]
    assert "18.6" in text["two_modes"]


def test_a_softening_mode_is_not_two_modes_and_few_levels_or_a_flat_backbone_are_named():
    q = np.geomspace(0.01, 1.0, 6)
    f = 100 * (1 - 0.4 * q)  # 40% softening, ordered by amplitude: one mode
    kinds = [k for k, _ in data_problem(_data(q, f, np.full(6, 0.02)), noise=(1e-3, 0.02))]
    assert kinds == []
    kinds = [k for k, _ in data_problem(_data([0.1, 0.1, 0.2], [100, 100.1, 99.0], [0.02] * 3), noise=(1e-3, 0.02))]
    assert kinds == ["few_levels"]
    kinds = [k for k, _ in data_problem(_data(q, np.full(6, 100.0), np.full(6, 0.02)), noise=(1e-3, 0.02))]
    assert kinds == ["flat"]


def test_the_likelihood_stop_names_the_setting():
    q, f, z = _backbone(6, (0.0, 0.0))
    with pytest.raises(ValueError, match="posterior.noise_max"):
        LogPosterior(_data(q, f, z, noise=(0.9, 0.7)), SPACE, M)


def _chain(converged=True, modes=False, n=300):
    rng = np.random.default_rng(0)
    theta = np.array([TRUTH[p] for p in PARAMS])
    S = np.column_stack([SPACE.to_physical(SPACE.to_unit(theta) + 2e-3 * rng.standard_normal((n, 6))),
                         np.full((n, 2), [1e-4, 0.01])])
    label = np.zeros(n, int)
    if modes:
        label[: n // 3] = 1
        S[: n // 3, 0] *= 0.55
    return dict(tau_history=np.array([[6000.0, 590.0, 400.0]]), converged=np.array(converged),
                stop_reason=np.array("converged" if converged else "projected"), projected_steps=np.array(332914.0),
                samples=S, sample_mode=label)


def test_an_unconverged_or_multimodal_chain_identifies_no_parameter_and_says_what_to_run():
    names = [*PARAMS, "sigma_f", "sigma_zeta"]
    q, f, z = readouts(levels=(1, 2, 5, 10, 50, 70, 100))  # past macroslip: a settled chain identifies Fs, KT, k
    assert unsettled(_chain(), names) == ""
    settled = identified_table(_chain()["samples"], names, SPACE, q, f, z, m=M)[0].set_index("quantity")
    assert {"Fs", "KT", "k"} <= set(settled.index[settled["identified"]])
    why = unsettled(_chain(converged=False), names)
    assert "10.2 of the 50" in why and "max_steps: 333000" in why
    raw = identified_table(_chain()["samples"], names, SPACE, q, f, z, m=M, why_not=why)[0]
    assert raw["identified"].tolist() == settled.reset_index()["identified"].tolist()  # the information's judgement
    t = settled_table(raw).set_index("quantity")
    assert not t.loc[t["kind"] != "curve", "identified"].any() and (t.loc[t["kind"] != "curve", "why_not"] == why).all()
    assert t.loc[t["kind"] == "curve", "identified"].all()  # the curves at the measured amplitudes are the read-outs'
    assert settled_table(raw.drop(columns="why_not")).equals(raw.drop(columns="why_not"))
    why = unsettled(_chain(modes=True), names)
    assert "2 separated modes" in why and "mode 2 (33% of the draws): Fs" in why


@pytest.mark.slow  # a GA run
def test_the_posterior_stage_stops_on_two_modes_with_the_fix_not_the_noise_floors(tmp_path):
    """The held-out beam's stop, on files: 'noise floors [0.94 0.68] must be finite and below noise_max' became
    one sentence naming the two modes, their runs and `modal: {mode_hz: ...}`."""
    from jointcal.calibrate import CalibrationInputError, run_calibration
    from jointcal.io import write_csv_atomic
    from jointcal.measure.scatter import scatter
    from jointcal.posterior import PosteriorSettings
    from jointcal.posterior.stage import posterior_of

    level = np.repeat([0.05, 0.1, 0.15, 0.2, 0.25, 0.3], 2)
    slow = np.tile([True, False], 6)  # 70-110 Hz at 5 Hz/s (the 95 Hz mode), 0.5-110 Hz at 13.75 Hz/s (18.6 Hz)
    f = np.where(slow, 95.0 * (1 - 0.16 * level), 18.6 * (1 - 0.05 * level))
    table = pd.DataFrame(dict(run_id=[f"{'slow' if s else 'fast'}_{v:g}V" for s, v in zip(slow, level)],
                              assembly="beam", level_V=level, direction="up", q_in=level * np.where(slow, 1.0, 26.0),
                              f_res_hz=f, zeta_res=np.where(slow, 0.018, 0.006) * (1 + level), flags=""))
    write_csv_atomic(table, tmp_path / "modal_properties.csv")
    write_csv_atomic(scatter(table), tmp_path / "scatter.csv")
    cal = CalibrateSettings()
    run_calibration(tmp_path / "modal_properties.csv", "beam", tmp_path / "cal", cal)
    with pytest.raises(CalibrationInputError) as err:
        posterior_of(tmp_path / "modal_properties.csv", tmp_path / "scatter.csv", tmp_path / "cal" / "ga_best.json",
                     "beam", cal, PosteriorSettings())
    text = str(err.value)
    assert "two different modes" in text and "mode_hz: 9" in text and "slow_0.05V" in text and "fast_0.05V" in text
    assert "noise floors" not in text and text.count(". ") == 0  # one sentence
