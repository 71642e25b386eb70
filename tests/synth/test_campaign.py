"""Synthetic campaigns (jointcal.synth.campaign): the truth is recovered, each hidden
effect leaves its signature, the DAQ's noise, quantisation and offsets are the spec's."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.io import ingest_campaign, read_manifest, read_run
from jointcal.models import G, MinistackModel
from jointcal.models.structure import state_space
from jointcal.synth import generate
from tests._support.lockin import run_amplitudes, run_quadrature

FIRST = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}
REASSEMBLY = {"Fs": 274.0, "KT": 0.90e6, "chi": -0.61, "beta": 0.025, "k": 8.56e5, "zeta_v": 0.0017}


def _campaign(tmp, name, **spec):
    out = Path(tmp) / name
    table = generate(spec, out, Path(tmp) / f"{name}_truth.json")
    man = read_manifest(out / "manifest.csv")
    runs = {r["run_id"]: read_run(out / r["file"]) for r in man.to_dict("records")}
    man = man.set_index("run_id", drop=False)
    man.attrs.update(folder=out, spec=spec)
    return man, runs, table.set_index("run_id")


@pytest.fixture(scope="module")
def slow_clean(tmp_path_factory):
    """No hidden effect, slow sweeps (eta <= 0.04), both assemblies, 1 and 10 g, up and down."""
    return _campaign(tmp_path_factory.mktemp("slow"), "clean", seed=11,
                     sweep={"f_start_hz": 1950.0, "f_stop_hz": 2500.0, "rate_hz_per_s": 60.0},
                     series=[{"level_g": 1.0, "directions": ["up", "down"]},
                             {"level_g": 10.0, "directions": ["up", "down"]}],
                     assemblies={"first": FIRST, "reassembly": REASSEMBLY})


@pytest.mark.slow
def test_clean_slow_sweeps_match_harmonic_balance_truth(slow_clean):
    man, runs, truth = slow_clean
    for rid, row in man.iterrows():
        tr = truth.loc[rid]
        f, q, a = run_quadrature(runs[rid], row, tr.f_hb_hz)
        zeta = a * G / (2 * (2 * np.pi * f) ** 2 * q)
        assert abs(f / tr.f_hb_hz - 1) < 5e-4, (rid, f, tr.f_hb_hz)
        assert abs(zeta / tr.zeta_hb - 1) < 0.02, (rid, zeta, tr.zeta_hb)
        assert q == pytest.approx(tr.q_hb_in, rel=0.03)


@pytest.mark.slow
def test_campaign_is_in_the_contract_and_deterministic(slow_clean, tmp_path):
    man, runs, truth = slow_clean
    table = ingest_campaign(man.attrs["folder"])
    assert len(table) == len(man) and (table["flags"].fillna("") == "").all()
    again, again_runs, again_truth = _campaign(tmp_path, "again", **man.attrs["spec"])
    for rid in man.index:
        pd.testing.assert_frame_equal(again_runs[rid], runs[rid])
    pd.testing.assert_frame_equal(again_truth, truth)


# -- hidden effects: each against the same campaign (same seed) without it -------------------

BAND = {"f_start_hz": 700.0, "f_stop_hz": 2500.0, "rate_hz_per_s": 400.0}
SERIES = [{"level_g": 1.0, "directions": ["up"]}, {"level_g": 10.0, "directions": ["up"]}]


@pytest.fixture(scope="module")
def effect_lab(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("effects")
    made = {}

    def make(effect, params=None, series=SERIES):
        key = (effect, str(params), str(series))
        if key not in made:
            made[key] = _campaign(tmp, f"{effect}_{len(made)}", seed=5, sweep=BAND, series=series,
                                  assemblies={"first": FIRST}, effect={"name": effect, "params": params or {}})
        return made[key]
    return make


def _res(camp, rid_suffix):
    man, runs, truth = camp
    rid = next(r for r in man.index if r.endswith(rid_suffix))
    f, q, a = run_quadrature(runs[rid], man.loc[rid], truth.loc[rid].f_hb_hz)
    return f, a * G / (2 * (2 * np.pi * f) ** 2 * q)


@pytest.mark.slow
def test_channel_delay_shifts_cross_phase_by_2_pi_f_tau(effect_lab):
    tau = 60e-6
    base, eff = effect_lab("none"), effect_lab("channel_delay", {"tau_s": tau})
    freqs = np.arange(800.0, 2450.0, 100.0)
    for rid in base[0].index:
        R0, B0 = run_amplitudes(base[1][rid], base[0].loc[rid], freqs, cycles=200)
        R1, B1 = run_amplitudes(eff[1][rid], eff[0].loc[rid], freqs, cycles=200)
        dphi = np.angle((R1 / B1) / (R0 / B0))
        tau_fit = -np.sum(dphi * freqs) / np.sum(2 * np.pi * freqs**2)  # least squares through 0
        assert tau_fit == pytest.approx(tau, rel=0.01)
        assert np.max(np.abs(dphi + 2 * np.pi * freqs * tau)) < 3e-3  # rad: sensor noise only


@pytest.mark.slow
def test_sensor_gain_scales_response(effect_lab):
    base, eff = effect_lab("none"), effect_lab("sensor_gain", {"gain": 1.3})
    freqs = np.array([900.0, 1800.0, 2300.0])
    for rid in base[0].index:
        R0, _ = run_amplitudes(base[1][rid], base[0].loc[rid], freqs)
        R1, _ = run_amplitudes(eff[1][rid], eff[0].loc[rid], freqs)
        np.testing.assert_allclose(np.abs(R1 / R0), 1.3, rtol=3e-3)


@pytest.mark.slow
def test_joint_settling_drifts_the_1g_repeats_monotonically(effect_lab):
    series = [{"level_g": 1.0, "directions": ["up"], "repeats": 4}]
    eff = effect_lab("joint_settling", None, series)
    base = effect_lab("none", None, series)
    f_eff = [_res(eff, f"_{n:02d}_1g_up")[0] for n in range(1, 5)]
    f_base = [_res(base, f"_{n:02d}_1g_up")[0] for n in range(1, 5)]
    scatter = np.ptp(f_base)  # Hz: repeat-to-repeat scatter (noise, controller ripple)
    assert np.all(np.diff(f_eff) > 0)  # a settling slug stiffens run after run
    assert f_eff[-1] - f_eff[0] > 5 * scatter and scatter < 3.0
    truth_f = eff[2]["f_hb_hz"].to_numpy()
    assert np.all(np.diff(truth_f) > 0)


@pytest.mark.slow
def test_a_campaign_generated_in_parts_continues_the_settling_along_its_sequence(effect_lab, tmp_path):
    """A second part (first_sequence 3: a campaign generated one spec per sweep rate) holds runs 3 and 4 of the
    lab's sequence, and its joint has settled as far as the one-part campaign's runs 3 and 4 (the truth's
    first-harmonic frequency, the drift X (1 + d (1 - exp(-(n - 1) / n_settle))) at n = 3, 4)."""
    series = [{"level_g": 1.0, "directions": ["up"], "repeats": 4}]
    whole = effect_lab("joint_settling", None, series)[2]
    man, _, part = _campaign(tmp_path, "part", seed=5, sweep=BAND, assemblies={"first": FIRST},
                             series=[{"level_g": 1.0, "directions": ["up"], "repeats": 2}], first_sequence=3,
                             effect={"name": "joint_settling", "params": {}})
    assert list(man["sequence"]) == [3, 4] and all(f"_{n:02d}_1g_up" in r for n, r in zip((3, 4), man.index))
    np.testing.assert_allclose(part["f_hb_hz"].to_numpy(), whole["f_hb_hz"].to_numpy()[2:], rtol=1e-12)
    assert part["f_hb_hz"].iloc[0] > whole["f_hb_hz"].iloc[1]  # not restarted at the part's first run
    with pytest.raises(ValueError, match="first_sequence must be an integer >= 1"):
        generate({"seed": 5, "first_sequence": 0}, tmp_path / "bad", tmp_path / "bad_truth.json")


@pytest.mark.slow
def test_cubic_stiffening_raises_high_level_resonance(effect_lab):
    base, eff = effect_lab("none"), effect_lab("cubic_stiffening")
    d1 = _res(eff, "1g_up")[0] / _res(base, "1g_up")[0] - 1
    d10 = _res(eff, "10g_up")[0] / _res(base, "10g_up")[0] - 1
    assert d10 > 0.01 and d10 > 5 * abs(d1)


@pytest.mark.slow
def test_quadratic_damping_raises_high_level_damping_more(effect_lab):
    base, eff = effect_lab("none"), effect_lab("quadratic_damping")
    r1 = _res(eff, "1g_up")[1] / _res(base, "1g_up")[1]
    r10 = _res(eff, "10g_up")[1] / _res(base, "10g_up")[1]
    assert r10 > 1.2 and r10 > r1 > 1.0


@pytest.mark.slow
def test_fixture_flexibility_amplifies_by_the_cans_dynamic_factor(effect_lab):
    params = {"m_can_ratio": 4.0, "f_can_hz": 5500.0}
    base, eff = effect_lab("none"), effect_lab("fixture_flexibility", params)
    freqs = np.array([800.0, 1000.0, 1300.0])
    rid = base[0].index[0]  # 1 g: the joint stays close to stuck off resonance
    R0, B0 = run_amplitudes(base[1][rid], base[0].loc[rid], freqs)
    R1, B1 = run_amplitudes(eff[1][rid], eff[0].loc[rid], freqs)
    m = 2.65 / G
    from jointcal.models import Fixture
    stuck = MinistackModel(m=m, k=FIRST["k"] + FIRST["KT"], zeta_v=FIRST["zeta_v"])
    can = MinistackModel(m=m, k=FIRST["k"] + FIRST["KT"], zeta_v=FIRST["zeta_v"],
                         fixture=Fixture(params["m_can_ratio"] * m, params["f_can_hz"], 0.01))  # the effect's zeta_can

    def T(model, f):
        ss = state_space(model)
        X = np.linalg.solve(2j * np.pi * f * np.eye(ss.A.shape[0]) - ss.A, ss.bu)
        return ss.cy @ X + ss.dyu
    expected = np.array([T(can, f) / T(stuck, f) for f in freqs])
    measured = (R1 / B1) / (R0 / B0)
    np.testing.assert_allclose(np.abs(measured), np.abs(expected), rtol=0.01)
    assert np.all(np.abs(expected) > 1.02)
    # and the slug resonance moves down by a few percent
    assert 0.005 < 1 - _res(eff, "1g_up")[0] / _res(base, "1g_up")[0] < 0.06


@pytest.mark.slow
def test_noise_quantisation_and_offsets_are_what_the_spec_asks(tmp_path):
    meas = {"noise_fraction": 0.01, "dc_offset_g": 0.05, "bits": 16,
            "full_scale_g": {"base": 20.0, "response": 200.0}}
    man, runs, truth = _campaign(tmp_path, "daq", seed=3, sweep={**BAND, "tail_s": 0.3}, series=SERIES,
                                 assemblies={"first": FIRST}, measurement=meas)
    for rid, row in man.iterrows():
        df, tr = runs[rid], truth.loc[rid]
        for ch, fs_g, off in (("base_accel_g", 20.0, tr.dc_offset_base_g), ("response_accel_g", 200.0,
                                                                              tr.dc_offset_response_g)):
            x = df[ch].to_numpy()
            lsb = 2 * fs_g / 2**16
            assert np.max(np.abs(x / lsb - np.round(x / lsb))) < 1e-3  # 16-bit codes
            tail = x[df["time_s"].to_numpy() > df["time_s"].iloc[-1] - 0.2]  # at rest: offset + noise
            sigma = 0.01 * np.sqrt(np.mean((x - off) ** 2))
            assert np.mean(tail) == pytest.approx(off, abs=4 * sigma / np.sqrt(tail.size) + lsb)
            assert np.std(tail) == pytest.approx(sigma, rel=0.08)


@pytest.mark.slow
def test_contact_spring_acts_beyond_its_gap_with_even_harmonics(effect_lab):
    """contact_spring (gap 8e-5 in): at 1 g the slug (q ~ 5e-5 in) never reaches the stop, so the run is
    the base run; at 10 g (q ~ 2.9e-4 in) the stop stiffens the resonance and the asymmetric force puts
    a 2nd harmonic in the response that dominates the 3rd (the joint's own harmonics are odd)."""
    from jointcal.measure.modal import measure_run
    base, eff = effect_lab("none"), effect_lab("contact_spring")

    def props(camp, suffix):
        man, runs, _ = camp
        rid = next(r for r in man.index if r.endswith(suffix))
        return measure_run(runs[rid], {**man.loc[rid].to_dict(), "run_id": rid})[2]

    b1, e1, b10, e10 = props(base, "1g_up"), props(eff, "1g_up"), props(base, "10g_up"), props(eff, "10g_up")
    assert abs(e1["f_res_hz"] / b1["f_res_hz"] - 1) < 1e-5
    assert e10["f_res_hz"] / b10["f_res_hz"] - 1 > 0.01
    assert e10["h2_ratio"] > 10 * b10["h2_ratio"] and e10["h2_ratio"] > 2 * e10["h3_ratio"]
    assert b10["h2_ratio"] < 0.5 * b10["h3_ratio"]
