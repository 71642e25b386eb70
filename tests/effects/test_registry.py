"""The effects registry: one home per effect, read by the schema, synth, both models and diagnose.

The toy effect below lives in a module written to a temporary folder and registered at run
time: it reaches the virtual lab, the envelope model, the time simulation and the discrepancy
workflow with no other file touched. Oracles: the Duffing oscillator's closed forms (its
free-vibration period by quadrature of the energy, its first-harmonic amplitude equation).
"""
from __future__ import annotations

import importlib
import json
import pkgutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.integrate import quad

import jointcal.effects as effects
from jointcal.calibrate.space import PARAMS
from jointcal.effects import EFFECTS, Effect, EffectParam, library, register
from jointcal.models import G, MinistackModel, simulate, steady_state

ROOT = Path(__file__).resolve().parents[2]
M = 2.65 / G
TOY = '''
"""foam_spring: a hardening foam pad beside the joint, k_foam z^3 (a toy effect for the tests)."""
from dataclasses import replace

from jointcal.effects import Effect, EffectParam, register
from jointcal.models import cubic_spring


def _apply(model, v, row):
    return replace(model, elements=model.elements + (cubic_spring(v["k_foam"]),))


def _fingerprint(fp, sigma_db, sigma_f):
    ft = fp.get("f_trend_per_decade") or 0.0
    return ft > 3 * sigma_f, f"the resonance rises by {ft * 100:+.2f}% per decade of level"


EFFECT = register(Effect(
    "foam_spring", (EffectParam("k_foam", "lbf/in^3", 0.0, 5e13, False, 1e11, "foam pad's cubic stiffness"),),
    _apply, lambda v: f"a foam pad stiffens the mount (k_foam = {v['k_foam']:.3g} lbf/in^3)", _fingerprint,
    hidden={"k_foam": 2e12}))
'''


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """The toy effect, imported from a module in a temporary folder (registered on import)."""
    (tmp_path / "toy_foam.py").write_text(TOY)
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("toy_foam")
    yield module.EFFECT
    EFFECTS.pop("foam_spring", None)
    sys.modules.pop("toy_foam", None)


def test_config_schema_lists_the_library():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    cand = schema["properties"]["discrepancy"]["properties"]["candidates"]
    assert cand["items"]["enum"] == list(library()) and cand["default"] == list(library())
    config = yaml.safe_load((ROOT / "workflow" / "config" / "config.yaml").read_text())
    assert config["discrepancy"]["candidates"] == list(library())


def test_docs_tables_list_the_registry():
    """The README's effect table and the package docstring's name every registered effect, in order."""
    readme = (ROOT / "README.md").read_text()
    table = readme[readme.index("## Effects (`jointcal.effects`)"):].split("\n\n")[2]
    assert [r.split("`")[1] for r in table.splitlines()[2:]] == list(EFFECTS)
    rows = effects.__doc__.split("=====\n")[2].splitlines()
    assert [r.split()[0] for r in rows if r and not r.startswith((" ", "="))] == list(EFFECTS)


def test_every_effect_module_is_registered_once():
    modules = [m.name for m in pkgutil.iter_modules(effects.__path__) if m.name not in ("effect", "registry")]
    assert sorted(modules) == sorted(EFFECTS)
    for name in modules:
        assert importlib.import_module(f"jointcal.effects.{name}").EFFECT is EFFECTS[name]
    assert "contact_spring" in EFFECTS and "contact_spring" not in library()  # kept out of the library on purpose


def test_registry_refuses_clashing_or_malformed_effects():
    with pytest.raises(ValueError, match="already belong to"):
        register(Effect("gain_again", (EffectParam("gain", "-", 0.5, 2.0, True, 1.0, ""),), None, None))
    with pytest.raises(ValueError, match="reserved"):
        register(Effect("a+b", (EffectParam("x9", "-", 0.5, 2.0, True, 1.0, ""),), None, None))
    with pytest.raises(ValueError, match="lo > 0 on a log"):
        EffectParam("x", "-", 0.0, 1.0, True, 0.5, "")


def test_toy_effect_in_the_time_simulation_matches_the_duffing_period(toy):
    """Undamped slug on k with the toy's k_foam z^3: after a bump, free vibration of amplitude A has
    the period 4 int_0^A dz / sqrt(2 (V(A) - V(z)) / m), V = k z^2 / 2 + k_foam z^4 / 4. Converged steps
    (8 per sample; the default, set by the linear frequency, is 0.3% off at this strong a hardening: the
    foam's force is a third of the spring's)."""
    k, kf, fs = 6e5, 2e11, 25600.0
    model = toy.apply(MinistackModel(m=M, k=k, zeta_v=0.0), {"k_foam": kf}, {})
    t = np.arange(int(fs * 0.3)) / fs
    a = 200.0 * np.where(t < 2e-4, 1.0, 0.0) * np.sin(np.pi * t / 2e-4)
    z = simulate(model, a, fs, n_sub=8).z_in[100:]
    tz = t[100:]
    A = 0.5 * (z.max() - z.min())
    V = lambda x: 0.5 * k * x**2 + 0.25 * kf * x**4
    period = 4 * quad(lambda x: 1 / np.sqrt(2 * (V(A) - V(x)) / M), 0, A, limit=200)[0]
    i = np.where((z[:-1] < 0) & (z[1:] >= 0))[0]
    tc = tz[i] - z[i] * (tz[i + 1] - tz[i]) / (z[i + 1] - z[i])
    linear = 2 * np.pi / np.sqrt(k / M)
    assert period < 0.97 * linear  # the foam matters: 3% or more stiffer than the linear spring
    assert abs((tc[-1] - tc[0]) / (len(tc) - 1) / period - 1) < 2e-6


def test_toy_effect_in_the_envelope_model_solves_the_duffing_first_harmonic(toy):
    """Steady state q of m z'' + c z' + k z + k_foam z^3 = -m a_b: |k + 3/4 k_foam q^2 - m w^2 + i w c| q = m A,
    and the sweep takes the other branch going down past the fold."""
    k, zeta, kf = 6e5, 0.01, 2e12
    model = toy.apply(MinistackModel(m=M, k=k, zeta_v=zeta), {"k_foam": kf}, {})
    f = np.linspace(1300, 1800, 1001)
    w = 2 * np.pi * f
    c = 2 * zeta * np.sqrt(k * M)
    for direction in ("up", "down"):
        ss = steady_state(model, f, 2.0, direction=direction)
        q = ss.q_in
        np.testing.assert_allclose(np.abs(k + 0.75 * kf * q**2 - M * w**2 + 1j * w * c) * q, M * 2.0 * G, rtol=1e-8)
    up, down = (steady_state(model, f, 2.0, direction=d).q_in for d in ("up", "down"))
    assert np.max(up / down) > 1.5  # a hardening fold: the up sweep stays on the upper branch longer


@pytest.mark.slow
def test_toy_effect_runs_through_synth_and_diagnose(toy, tmp_path):
    """A virtual campaign hides the toy effect; diagnose fits it beside the baseline and a library
    effect, sees its fingerprint, names it and recovers its parameter (within 5% on a one-generation
    recalibration)."""
    from jointcal.discrepancy import DiscrepancySettings, diagnose
    from jointcal.io import read_manifest, read_run, write_csv_atomic
    from jointcal.measure.modal import measure_run
    from jointcal.measure.scatter import scatter
    from jointcal.synth import generate

    truth = dict(Fs=280.0, KT=1.1e6, chi=-0.6, beta=0.01, k=7.0e5, zeta_v=0.002)
    spec = {"seed": 3, "sample_rate_hz": 10000.0,
            "sweep": {"f_start_hz": 1700.0, "f_stop_hz": 2700.0, "rate_hz_per_s": 400.0},
            "series": [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 2},
                       {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}],
            "assemblies": {"a": truth}, "effect": {"name": "foam_spring"}}
    generate(spec, tmp_path / "c", tmp_path / "truth.json")
    assert json.loads((tmp_path / "truth.json").read_text())["effect"]["params"] == {"k_foam": 2e12}
    rows, envs, records, props = [], {}, [], []
    for row in read_manifest(tmp_path / "c" / "manifest.csv").to_dict("records"):
        rec = read_run(tmp_path / "c" / row["file"])
        env, _, p = measure_run(rec, row)
        rows.append(row)
        envs[row["run_id"]] = env
        records.append(rec)
        props.append({**p, "assembly": "a"})
    table = pd.DataFrame(props)
    write_csv_atomic(scatter(table), tmp_path / "scatter.csv")
    best = {**truth, "m": M, "viscous": "dashpot"}
    s = DiscrepancySettings(candidates=("sensor_gain", "foam_spring"), ga_generations=1, posterior_steps=100,
                            max_nfev=8, max_frames=24)
    from jointcal.calibrate import CalibrateSettings
    d = diagnose("a", envs, table, best, None, records, rows, space=CalibrateSettings().space, settings=s)["diagnosis"]
    print(f"\n{d['effect']} ({d['confidence']}): baseline E {d['baseline']['E_fit']:.2f}, "
          + ", ".join(f"{c['name']} {c['E_fit']:.2f}" for c in d["candidates"]))
    cand = {c["name"]: c for c in d["candidates"]}
    assert set(cand) == {"sensor_gain", "foam_spring"}
    toy_c = cand["foam_spring"]
    assert toy_c["effect_parameters"]["k_foam"]["unit"] == "lbf/in^3"
    assert toy_c["fingerprints_for"] == [w for w in toy_c["fingerprints_for"] if "per decade of level" in w] != []
    assert toy_c["E_fit"] < 0.2 * d["baseline"]["E_fit"] and d["effect"] == "foam_spring"
    k_foam = d["recalibrated"]["effect_parameters"]["k_foam"]["value"]
    print(f"k_foam {k_foam:.3g} lbf/in^3 (hidden 2e12)")
    assert abs(k_foam / 2e12 - 1) < 0.05
    assert d["rule"] and d["rule_applied"] and all(c in d["rule"] for c in d["rule_applied"])
    assert set(PARAMS) <= set(d["baseline"]["joint_parameters"])


def test_each_kind_tries_its_own_library():
    assert set(library("modal")) == {"channel_delay", "cubic_stiffening", "joint_settling", "elastic_softening",
                                     "neighbour_mode"}
    assert "sensor_gain" in library("ministack") and "elastic_softening" not in library("ministack")


def test_the_neighbours_shaker_loop_is_fitted_on_voltage_sweeps_only():
    """neighbour_mode's loop constants are parameters where the sweeps are voltage-driven (scales["voltage"]) and
    nowhere else; with them zero its model is the added mode, with them set the neighbour sits in the loop."""
    from jointcal.effects import EFFECTS
    from tests._support.rigs import rig

    e = EFFECTS["neighbour_mode"]
    scales = {"K0": 1022.0, "f0": 100.0, "q": 0.01}
    assert [p.name for p in e.params_for(scales)] == ["f_ratio", "mode_ratio"]
    assert [p.name for p in e.params_for(None)] == ["f_ratio", "mode_ratio"]
    assert [p.name for p in e.params_for({**scales, "voltage": 1.0})] == ["f_ratio", "mode_ratio", "loop_armature",
                                                                          "back_emf_share", "read_gain", "read_phase"]
    model = rig()[0]
    plain = e.apply(model, {"f_ratio": 1.5, "mode_ratio": 4.0}, {})
    looped = e.apply(model, {"f_ratio": 1.5, "mode_ratio": 4.0, "loop_armature": 0.05, "back_emf_share": 0.3},
                     {})
    assert not plain.neighbour.looped and looped.neighbour.looped
    assert looped.neighbour.f_ref_hz == pytest.approx(model.f0_hz, rel=1e-12)
    assert looped.neighbour.back_emf == pytest.approx(0.3 * 2 * model.zeta_v, rel=1e-12)  # a share of 2 zeta_v
    loop_words = e.advice({"f_ratio": 1.5, "mode_ratio": 4.0, "loop_armature": 0.047, "back_emf_share": 0.35,
                           "read_gain": 1.31, "read_phase": -0.05})
    assert "armature (0.047" in loop_words and "0.35 of its viscous damping" in loop_words and "1.310 x" in loop_words
    assert "armature" not in e.advice({"f_ratio": 1.5, "mode_ratio": 4.0})
