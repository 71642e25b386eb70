"""Calibration stage: eq. 3.9, the DEAP GA, the modal-table contract and the stage's files.

Synthetic modal tables (tests/_modal_tables.py) play the modal stage: the harmonic-balance
resonance of a known joint at the Table 3.1 levels, with 0.02% noise on f and 1% on zeta.
"""
from __future__ import annotations

import importlib
import json
import multiprocessing
import warnings

import numpy as np
import pandas as pd
import pytest
import yaml
from tests._support.campaign import REPO
from tests._support.modal_tables import LEVELS, M, TABLE_3_2, modal_tables, write_tables

from jointcal.calibrate import (
    PARAMS, PENALTY, UNITS, CalibrateSettings, CalibrationInputError, GAOptions, ParamSpace, calibrate, objective,
    predict, read_modal, run_calibration, run_ga, select_modal,
)
from jointcal.models import harmonic_balance, resonance_amplitude

FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])
SPACE = CalibrateSettings().space


def _data(truth=TABLE_3_2["first"], seed=1, noise=(2e-4, 0.01)):
    modal, scatter = modal_tables({"first": truth}, rel_noise=noise, seed=seed)
    return select_modal(modal, "first", scatter=scatter)


# ---------------------------------------------------------------- parameter space

def test_space_round_trip_and_scaling():
    p = np.array([FIRST, [1.0, 1e4, -0.95, 1e-4, 1e4, 1e-4], [1e4, 1e8, 0.0, 5.0, 1e8, 0.1]])
    u = SPACE.to_unit(p)
    np.testing.assert_allclose(u[1], 0.0, atol=1e-12)
    np.testing.assert_allclose(u[2], 1.0, atol=1e-12)
    np.testing.assert_allclose(SPACE.to_physical(u), p, rtol=1e-12)
    assert SPACE.x_names == ("log10_Fs", "log10_KT", "chi", "log10_beta", "log10_k", "log10_zeta_v")
    # a decade of Fs is a quarter of its gene range (1..1e4 lbf, log-scaled); chi is linear
    assert SPACE.to_unit([[10.0, 1e6, -0.475, 0.01, 1e6, 0.01]])[0, 0] == pytest.approx(0.25)
    assert SPACE.to_unit([[10.0, 1e6, -0.475, 0.01, 1e6, 0.01]])[0, 2] == pytest.approx(0.5)


def test_space_grows_by_named_parameters_with_their_scaling():
    """ParamSpace.grow appends columns (an effect's), each with its bounds and log/linear scaling;
    the joint's six columns map exactly as before."""
    g = SPACE.grow(["gain", "tau_s"], [0.5, 0.0], [2.0, 4e-4], [True, False])
    assert g.names == (*PARAMS, "gain", "tau_s") and g.ndim == 8
    u = np.array([0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.5, 0.25])
    th = g.to_physical(u)
    np.testing.assert_allclose(th[:6], SPACE.to_physical(u[:6]), rtol=1e-14)
    assert th[6] == pytest.approx(1.0) and th[7] == pytest.approx(1e-4)  # log mid of [0.5, 2]; linear quarter
    np.testing.assert_allclose(g.to_unit(th), u, atol=1e-12)
    with pytest.raises(ValueError, match="log-scaled"):
        SPACE.grow(["tau_s"], [0.0], [1e-4], [True])
    with pytest.raises(ValueError, match="repeat"):
        SPACE.grow(["Fs"], [1.0], [2.0], [True])


def test_a_grown_space_reads_the_joint_by_name():
    """Named access of a grown space: columns, the joint's six, its model and the stuck stiffness and macroslip
    onset, against values written by hand (eq. 3.7: phi_max = Fs (1 + beta) / (KT (beta + (chi+1)/(chi+2))))."""
    g = SPACE.grow(["gain"], [0.5], [2.0], [True], ["-"])
    joint = {"Fs": 280.0, "KT": 1.1e6, "chi": -0.6, "beta": 0.01, "k": 7.0e5, "zeta_v": 0.002}
    th = g.vector({**joint, "gain": 1.12})
    assert g.units == (*(UNITS[p] for p in PARAMS), "-") and g.extra == ("gain",)
    assert g.column(th, "gain") == 1.12 and g.named(th)["zeta_v"] == 0.002
    np.testing.assert_array_equal(g.joint(np.stack([th, th])), [list(joint.values())] * 2)
    assert g.stuck_stiffness(th) == pytest.approx(1.8e6, rel=1e-15)
    c = 0.01 + 0.4 / 1.4
    assert g.phi_max(th) == pytest.approx(280.0 * 1.01 / (1.1e6 * c), rel=1e-12)
    stiffer = g.vector({**joint, "k": 1.4e6, "gain": 1.0})
    model = g.model(np.stack([th, stiffer]), m=0.01)  # batched: fields (P, 1)
    assert model.iwan.Fs.shape == (2, 1) and model.k[1, 0] == 1.4e6 and model.m == 0.01
    assert g.model(th, m=0.01).iwan.chi == -0.6
    with pytest.raises(ValueError, match="missing: gain"):
        g.vector(joint)
    with pytest.raises(KeyError, match="tau_s"):
        g.column(th, "tau_s")


@pytest.mark.parametrize("bounds, match", [
    ({"Fs": [0.0, 10.0]}, "Fs.*lower bound must be > 0"),
    ({"chi": [-1.2, 0.0]}, "chi must lie in"),
    ({"KT": [1e6, 1e5]}, "lower < upper"),
    ({"kappa": [1.0, 2.0]}, r"unknown parameter\(s\) kappa; they are Fs, KT"),
])
def test_space_rejects_bad_bounds(bounds, match):
    with pytest.raises(ValueError, match=match):
        CalibrateSettings.from_config({"bounds": bounds})


# ---------------------------------------------------------------- objective (eq. 3.9)

def test_objective_is_eq_3_9_and_vectorised():
    d = _data()
    rng = np.random.default_rng(3)
    pop = SPACE.to_physical(rng.random((50, 6)))
    pop[0] = FIRST
    got = objective(pop, d.q, d.f, d.zeta, m=M, eta=0.7)
    f, z = harmonic_balance(d.q, *FIRST[:5], M, FIRST[5])
    by_hand = 0.7 * np.mean(((d.f - f) / d.f) ** 2) + 0.3 * np.mean(((d.zeta - z) / d.zeta) ** 2)
    assert got[0] == pytest.approx(by_hand, rel=1e-12)
    one_by_one = [objective(p[None], d.q, d.f, d.zeta, m=M, eta=0.7)[0] for p in pop]
    np.testing.assert_allclose(got, one_by_one, rtol=1e-12)


def test_objective_is_zero_on_exact_data_and_penalises_invalid_rows():
    q, f, z = resonance_amplitude(np.array(LEVELS, float), *FIRST[:5], M, FIRST[5])
    pop = np.array([FIRST, FIRST * [1, 1, np.nan, 1, 1, 1], FIRST * [1, 1, 1.6, 1, 1, 1], FIRST])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = objective(pop, q, f, z, m=M, valid=[True, True, True, False])
    assert got[0] < 1e-20  # exact data: only rounding (absolute tolerance, Gamma = 0 in exact arithmetic)
    assert got[1] == PENALTY and got[2] == PENALTY and got[3] == PENALTY  # NaN, chi < -1, flagged invalid
    assert np.all(np.isfinite(got))


def test_qsma_sits_above_harmonic_balance_as_documented():
    q = np.array([5.1e-5, 2.9e-4])  # 1 g and 10 g of Table 3.2's first assembly
    fq, _ = predict(FIRST[None], q, m=M, model="qsma")
    fh, _ = predict(FIRST[None], q, m=M, model="harmonic_balance")
    np.testing.assert_allclose(100 * (fq / fh - 1)[0], [0.15, 0.35], atol=0.03)


# ---------------------------------------------------------------- the modal-table contract

def test_unusable_rows_are_left_out_other_flags_kept():
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    modal.loc[0, "flags"] = "low_snr;unusable"
    modal.loc[1, "flags"] = "eta_high"
    modal.loc[0, "q_in"] = np.nan  # an unusable row may hold NaN: never read
    d = select_modal(modal, "first", scatter=scatter)
    assert d.run_id == tuple(modal["run_id"][1:])
    assert "1 of 12 runs" in d.notes[0]


def _break(tmp_path, edit):
    modal_csv, scatter_csv = write_tables(tmp_path, {"first": TABLE_3_2["first"]}, seed=1)
    df = pd.read_csv(modal_csv)
    edit(df)
    df.to_csv(modal_csv, index=False)
    return modal_csv


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.pop("q_in"), "column(s) q_in missing"),
    (lambda d: d.__setitem__("flags", "unusable"), "all 12 runs of assembly 'first' are flagged unusable"),
    (lambda d: d.__setitem__("zeta_res", np.nan), "set calibrate.damping to zeta_phase_resonance"),
    (lambda d: d.__setitem__("assembly", "other"), "no runs of assembly 'first'"),
])
def test_bad_modal_table_is_one_sentence_naming_the_file(tmp_path, edit, message):
    modal_csv = _break(tmp_path, edit)
    with pytest.raises(CalibrationInputError) as err:
        read_modal(modal_csv, "first")
    text = str(err.value)
    assert text.startswith(f"{modal_csv}: ") and message in text and text.endswith(".") and "\n" not in text


def test_a_run_without_a_read_out_is_left_out_with_a_note(tmp_path):
    modal_csv = _break(tmp_path, lambda d: d.loc.__setitem__((3, "f_res_hz"), np.nan))
    d = read_modal(modal_csv, "first")
    assert "first_04_1g_down" not in d.run_id and len(d.run_id) == 11
    assert any("'first_04_1g_down' has no positive q_in, f_res_hz and zeta_res" in n and n.endswith("left out")
               for n in d.notes)


def test_a_voltage_campaign_asked_for_phase_resonance_damping_is_told_which_column_it_has():
    """A voltage-driven run has no phase-resonance damping (the voltage is not a force): the sentence says
    so and names the column to use instead of stopping on the first NaN."""
    modal, _ = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    modal = modal.rename(columns={"level_g": "level_V"}).assign(zeta_phase_resonance=np.nan)
    with pytest.raises(CalibrationInputError) as err:
        select_modal(modal, "first", damping="zeta_phase_resonance")
    text = str(err.value)
    assert "a voltage is not a force" in text and "set calibrate.damping to zeta_res" in text and "\n" not in text


def test_missing_table_names_the_file(tmp_path):
    with pytest.raises(CalibrationInputError, match="nowhere.csv: the file does not exist"):
        read_modal(tmp_path / "nowhere.csv", "first")


def test_missing_or_zero_pooled_scatter_falls_back_to_the_floor():
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    pooled_f = (scatter["source"] == "pooled") & (scatter["quantity"] == "f_res_hz")
    scatter.loc[pooled_f, "rel_std"] = 0.0
    scatter = scatter[~((scatter["source"] == "pooled") & (scatter["quantity"] == "zeta_res"))]
    d = select_modal(modal, "first", scatter=scatter, floors={"frequency": 3e-4, "damping": 0.02})
    assert d.rel_noise == (3e-4, 0.02)
    assert sum("using the floor" in n for n in d.notes) == 2


# ---------------------------------------------------------------- settings and DEAP hygiene

def test_config_snippet_equals_the_python_defaults():
    keys = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    # the one difference: the workflow takes the model kind from the campaign (auto), the API defaults to the paper's
    assert CalibrateSettings.from_config(keys["calibrate"]) == CalibrateSettings(model_kind="auto")
    with pytest.raises(ValueError, match="unknown key"):
        CalibrateSettings.from_config({"populaton": 10})


def test_reimporting_the_ga_module_does_not_recreate_creator_classes():
    import jointcal.calibrate.ga as ga

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # DEAP warns when a creator class is created twice
        importlib.reload(ga)


def test_interrupted_ga_resumes_to_the_same_end():
    d = _data()
    opt = GAOptions(population=30, offspring=30, generations=8, checkpoint_every=3, seed=5)
    batch = lambda u: objective(SPACE.to_physical(u), d.q, d.f, d.zeta, m=M, valid=SPACE.inside(u))  # noqa: E731
    states = []
    full = run_ga(batch, 6, opt, on_checkpoint=lambda s: states.append(__import__("pickle").dumps(s)))
    at3 = __import__("pickle").loads(states[0])
    assert at3["generation"] == 3
    resumed = run_ga(batch, 6, opt, resume=at3)
    np.testing.assert_array_equal(resumed.best, full.best)
    np.testing.assert_array_equal(resumed.history, full.history)
    assert list(resumed.logbook) == list(full.logbook)


# ---------------------------------------------------------------- GA runs (slow)

def _objectives_of_seed(seed: int) -> tuple[float, float]:
    cal = calibrate(_data(), CalibrateSettings.from_config({"seed": seed}))
    return cal.best["objective"], cal.best["objective_ga"]


@pytest.mark.slow
def test_five_seeds_reach_the_same_optimum():
    """(a) polished objectives of 5 seeds within 1% of the best (noisy data: the optimum is > 0).
    The seeds are independent GA runs (each single threaded): two at a time."""
    with multiprocessing.get_context("fork").Pool(2) as pool:
        out = pool.map(_objectives_of_seed, range(5))
    values, raw = np.array(out).T
    assert values.min() > 0
    assert np.all(values <= 1.01 * values.min()), values
    assert np.all(values <= raw)  # the polish never makes it worse


@pytest.mark.slow
@pytest.mark.parametrize("eta, f_tol", [(0.85, 0.15), (0.99, 0.05)])
def test_calibrated_curves_match_the_truth(eta, f_tol):
    """(b) on the GA's eq. 3.9 optimum. With eta = 0.85 (the paper) the 1% damping noise outweighs the
    0.02% frequency noise in eq. 3.9 and pulls the frequency curve off by up to ~0.1%; eta = 0.99
    meets 0.05%. (The posterior, which weights by the noise, is checked against 0.05% in test_posterior.)"""
    d = _data()
    cal = calibrate(d, CalibrateSettings.from_config({"eta": eta}))
    theta = np.array([cal.best[p] for p in PARAMS])
    q = np.geomspace(d.q.min(), d.q.max(), 60)
    f_t, z_t = harmonic_balance(q, *FIRST[:5], M, FIRST[5])
    f_c, z_c = harmonic_balance(q, *theta[:5], M, theta[5])
    assert np.max(np.abs(f_c / f_t - 1)) < f_tol / 100
    assert np.max(np.abs(z_c / z_t - 1)) < 0.02


@pytest.mark.slow
def test_qsma_calibration_absorbs_its_bias_into_the_parameters():
    """Data from harmonic balance (what a sweep shows), fitted with QSMA (the paper's model):
    QSMA fits the data as well (to 0.01%), but with another joint. Measured: the stuck stiffness
    k + KT comes out 0.5% high, chi 0.009 lower and zeta_v 30% low; the same parameters in harmonic
    balance (what the structure does) miss the measured frequencies by -0.18% (1 g) to -0.41%
    (10 g) and the damping by +0.3% to +0.8%."""
    d = _data(noise=(1e-5, 1e-3))
    hb = calibrate(d, CalibrateSettings.from_config({"model": "harmonic_balance", "eta": 0.99}))
    qs = calibrate(d, CalibrateSettings.from_config({"model": "qsma", "eta": 0.99}))
    t_hb = np.array([hb.best[p] for p in PARAMS])
    t_qs = np.array([qs.best[p] for p in PARAMS])
    f_fit, _ = predict(t_qs[None], d.q, m=M, model="qsma")
    f_as_hb, _ = predict(t_qs[None], d.q, m=M, model="harmonic_balance")
    assert np.max(np.abs(f_fit[0] / d.f - 1)) < 0.01e-2  # QSMA mimics the data ...
    miss = 100 * (f_as_hb[0] / d.f - 1)
    assert np.all(miss < -0.15) and miss.min() < -0.35  # ... with a joint that is 0.15-0.4% too soft
    k0 = lambda t: t[1] + t[4]  # noqa: E731
    assert k0(t_hb) == pytest.approx(k0(FIRST), rel=2e-4)  # harmonic balance recovers the truth's k + KT
    assert k0(t_qs) / k0(t_hb) - 1 > 2e-3  # QSMA's is off
    assert t_hb[2] == pytest.approx(FIRST[2], abs=2e-3) and abs(t_qs[2] - t_hb[2]) > 5e-3  # chi
    assert t_hb[5] == pytest.approx(FIRST[5], rel=0.02) and t_qs[5] < 0.8 * t_hb[5]  # zeta_v absorbs the rest


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
