"""The calibration's read-outs from ring-downs and dwells (jointcal.calibrate._readouts): a ring-down's windows and a
level's dwells' phase resonance, each read-out weighted once, in eq. 3.9 and the likelihood; and calibration from
virtual campaigns of ring-downs alone and of sweeps and ring-downs mixed, the posterior held against the truth."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import CalibrateSettings, objective, read_modal, run_calibration, select_modal
from jointcal.io import write_csv_atomic
from jointcal.measure.testkinds.read import backbone_table
from jointcal.models import harmonic_balance, resonance_amplitude
from jointcal.posterior import PosteriorSettings, run_posterior
from jointcal.posterior.identified import identified_table, quantities
from jointcal.synth import DEFAULT_SPEC, generate
from jointcal.units import G
from tests._support.campaign import modal_tables as campaign_tables
from tests._support.modal_tables import TABLE_3_2, modal_tables

FIRST = TABLE_3_2["first"]
M = DEFAULT_SPEC["slug_weight_lbf"] / G
JOINT = [FIRST[p] for p in ("Fs", "KT", "chi", "beta", "k")]


def _tables():
    """Six swept runs (ideal read-outs), a ring-down of 20 windows, and a level of three dwells with their own
    ring-down of 10 windows and their phase resonance."""
    modal, _ = modal_tables({"a": FIRST}, levels=(1, 1, 2, 2, 5, 5), seed=4)
    modal = modal.assign(mode="m2253", test="sweep", f_res_method="quadrature")
    q_rd = np.geomspace(1e-4, 1e-6, 20)
    f_rd, z_rd = harmonic_balance(q_rd, *JOINT, M, FIRST["zeta_v"])
    q_d, f_d, z_d = resonance_amplitude(3.0, *JOINT, M, FIRST["zeta_v"])
    rd = dict(run_id="rd", assembly="a", mode="m2253", level_g=10.0, test="ringdown", f_res_method="ringdown",
              q_in=q_rd[0], f_res_hz=f_rd[0], zeta_res=z_rd[0], flags="")
    dwells = [dict(run_id=f"d{i}", assembly="a", mode="m2253", level_g=3.0, test="dwell", f_res_method="dwell",
                   q_in=q_d * (0.8 + 0.1 * i), f_res_hz=f_d * (1 + 1e-4 * i), zeta_res=z_d * (1.05 - 0.05 * i),
                   q_dwell_quad_in=float(q_d), f_dwell_quad_hz=float(f_d), zeta_dwell_quad=float(z_d), flags="")
              for i in range(3)]
    modal = pd.concat([modal, pd.DataFrame([rd, *dwells])], ignore_index=True)
    for c in ("zeta_phase_resonance", "zeta_half_power"):
        modal[c] = modal[c].fillna(modal["zeta_res"])
    windows = pd.DataFrame({"run_id": "rd", "mode": "m2253", "test": "ringdown", "q_in": q_rd, "f_hz": f_rd,
                            "zeta": z_rd})
    own = windows.iloc[8:18].assign(run_id="d1")  # the middle dwell's record goes on into a ring-down
    dwell_pts = pd.DataFrame({"run_id": [d["run_id"] for d in dwells], "mode": "m2253", "test": "dwell",
                              "q_in": [d["q_in"] for d in dwells], "f_hz": [d["f_res_hz"] for d in dwells],
                              "zeta": [d["zeta_res"] for d in dwells]})
    return modal, backbone_table(modal.iloc[:6], []), windows, own, dwell_pts


def test_a_ring_down_weighs_one_read_out_and_a_level_of_dwells_gives_its_phase_resonance():
    modal, sweeps, windows, own, dwell_pts = _tables()
    backbone = pd.concat([sweeps, windows, own, dwell_pts], ignore_index=True)
    plain = select_modal(modal, "a")  # without backbone.csv: one point per run, as before
    assert plain.weight is None and plain.q.size == 10 and plain.n_readouts == 10
    data = select_modal(modal, "a", backbone=backbone)
    # 6 sweeps + the ring-down's 20 windows + the dwell's own 10 + the level's phase resonance
    assert data.q.size == 6 + 20 + 10 + 1 and data.n_readouts == pytest.approx(6 + 1 + 1 + 1)
    w = pd.Series(data.w, index=pd.Index(data.run_id))
    assert np.allclose(w["rd"], 1 / 20) and np.allclose(w["d1"], 1 / 10) and w["d0+d1+d2"] == 1.0
    assert (w.iloc[:6] == 1.0).all() and list(data.run_id[:6]) == list(modal["run_id"][:6])
    i = data.run_id.index("d0+d1+d2")  # the dwells' points (damping off resonance) are not read-outs
    q_d, f_d, z_d = resonance_amplitude(3.0, *JOINT, M, FIRST["zeta_v"])
    assert (data.q[i], data.f[i], data.zeta[i]) == (float(q_d), float(f_d), float(z_d))
    assert any("20 windows over 2.00 decades" in n for n in data.notes)
    # eq. 3.9 over read-outs: a ring-down's mean squared residual counts once, whatever its number of windows
    theta = np.array([[FIRST[p] * (1.02 if p == "Fs" else 1.0) for p in ("Fs", "KT", "chi", "beta", "k", "zeta_v")]])
    f_m, z_m = harmonic_balance(data.q, *(theta[0, :5]), M, theta[0, 5])
    rf, rz = (data.f - f_m) / data.f, (data.zeta - z_m) / data.zeta
    runs = pd.DataFrame({"run": data.run_id, "f": rf**2, "z": rz**2}).groupby("run", sort=False).mean()
    want = 0.85 * runs["f"].mean() + 0.15 * runs["z"].mean()
    got = objective(theta, data.q, data.f, data.zeta, m=M, weight=data.weight)[0]
    assert got == pytest.approx(want, rel=1e-12)
    # weights of one give eq. 3.9 as it was, to the bit (the sweeps' campaigns keep their results)
    assert objective(theta, plain.q, plain.f, plain.zeta, m=M, weight=np.ones(10))[0] == objective(
        theta, plain.q, plain.f, plain.zeta, m=M)[0]


def test_a_backbone_without_its_columns_is_one_sentence(tmp_path):
    modal, sweeps, windows, _, _ = _tables()
    write_csv_atomic(modal, tmp_path / "modal_properties.csv")
    write_csv_atomic(windows.drop(columns=["zeta"]), tmp_path / "backbone.csv")
    with pytest.raises(ValueError, match=r"backbone.csv: column\(s\) zeta missing .*; regenerate it with the modal"):
        read_modal(tmp_path / "modal_properties.csv", "a", backbone_csv=tmp_path / "backbone.csv")


def _test_kinds_alone(seed: int = 0) -> tuple[pd.DataFrame, pd.DataFrame, np.ndarray, np.ndarray]:
    """Three ring-downs of 20 windows each (their own standard errors, 3e-5 in f and 1% in zeta, and the noise
    drawn at them) and a level of three dwells, on a joint whose damping is not the Iwan's: the truth's frequency
    is Table 3.2's first joint's harmonic balance, its damping that of the same joint times 1 + 0.3 ln(q / 1e-5)
    (more dissipation growth than Masing's rules allow an Iwan joint with that softening). Returns the modal table,
    backbone.csv's rows, and the truth's f and zeta at the windows."""
    rng = np.random.default_rng(seed)
    grow = lambda q: 1.0 + 0.3 * np.log(q / 1e-5)  # noqa: E731
    rows, pts, f_true, z_true = [], [], [], []
    for i, top in enumerate((3e-5, 1e-4, 3e-4)):
        q = np.geomspace(top, top / 30, 20)
        f, z = harmonic_balance(q, *JOINT, M, FIRST["zeta_v"])
        z = z * grow(q)
        f_true.append(f)
        z_true.append(z)
        rid = f"rd{i}"
        rows.append(dict(run_id=rid, assembly="a", mode="m2253", level_g=[1.0, 3.0, 10.0][i], test="ringdown",
                         f_res_method="ringdown", q_in=q[0], f_res_hz=f[0], zeta_res=z[0], flags=""))
        pts.append(pd.DataFrame({"run_id": rid, "mode": "m2253", "test": "ringdown", "q_in": q,
                                 "f_hz": f * (1 + 3e-5 * rng.standard_normal(20)),
                                 "zeta": z * (1 + 0.01 * rng.standard_normal(20)),
                                 "window_s": 10 / f, "f_se_hz": 3e-5 * f, "zeta_se": 0.01 * z}))
    q_d, f_d, _ = resonance_amplitude(3.0, *JOINT, M, FIRST["zeta_v"])
    z_d = float(harmonic_balance(q_d, *JOINT, M, FIRST["zeta_v"])[1] * grow(q_d))
    for i in range(3):
        rows.append(dict(run_id=f"d{i}", assembly="a", mode="m2253", level_g=3.0, test="dwell", f_res_method="dwell",
                         q_in=q_d, f_res_hz=f_d, zeta_res=z_d, q_dwell_quad_in=float(q_d),
                         f_dwell_quad_hz=float(f_d), zeta_dwell_quad=z_d, flags=""))
    modal = pd.DataFrame(rows)
    for c in ("zeta_phase_resonance", "zeta_half_power"):
        modal[c] = modal["zeta_res"]
    return modal, pd.concat(pts, ignore_index=True), np.concatenate(f_true), np.concatenate(z_true)


def test_ring_downs_and_dwells_alone_are_polished_on_the_windows_standard_errors():
    """A campaign of test kinds alone (ring-downs and a level of dwells, no sweep) is polished on the windows' own
    standard errors, the level's phase resonance at the noise floors (1e-4, 0.01); one sweep among them keeps
    eq. 3.9. Oracle: the truth's frequency backbone (Table 3.2's first joint, harmonic balance). Its damping grows
    faster than an Iwan joint with that softening can follow, so no parameter set fits both; the windows resolve f
    to 0.6-1.1e-4 (their standard errors of 3e-5 floored as the validation floors them) and zeta to 1%, and on their
    scale the calibrated f stays nearer the truth's than eq. 3.9's does (its weight eta puts a relative f error of
    1e-4 level with a zeta error of 1e-2). Measured (seed 0, GA seed 2017): the rms relative error of f at the
    windows 0.0030 on the standard errors, 0.024 on eq. 3.9."""
    import dataclasses

    from jointcal.calibrate.fit import calibrate
    from jointcal.calibrate.ga import GAOptions
    from jointcal.measure.testkinds.ringdown import window_scales

    modal, backbone, f_true, _ = _test_kinds_alone()
    data = select_modal(modal, "a", backbone=backbone)
    assert data.sigma is not None and data.q.size == 60 + 1
    level = [i for i, r in enumerate(data.run_id) if "+" in r]  # the level's phase resonance: at the floors
    assert len(level) == 1 and data.sigma[0][level[0]] == 1e-4 and data.sigma[1][level[0]] == 0.01
    assert data.q_top[level[0]] == data.q[level[0]]
    scales = window_scales(backbone["f_hz"], backbone["zeta"], backbone["f_se_hz"], backbone["zeta_se"])
    assert np.array_equal(data.sigma[0][:60], scales[0]) and np.array_equal(data.sigma[1][:60], scales[1])
    sweep = dict(modal.iloc[0], run_id="s1", test="sweep", f_res_method="quadrature")
    assert select_modal(pd.concat([modal, pd.DataFrame([sweep])], ignore_index=True), "a",
                        backbone=backbone).sigma is None  # sweeps among them: eq. 3.9, as before
    s = CalibrateSettings(ga=GAOptions(population=60, offspring=60, generations=40), n_polish=4)
    err = {}
    for name, d in (("standard errors", data), ("eq. 3.9", dataclasses.replace(data, sigma=None, q_top=None))):
        best = calibrate(d, s).best
        f_m, _ = harmonic_balance(data.q[:60], *(best[p] for p in ("Fs", "KT", "chi", "beta", "k")), M,
                                  best["zeta_v"])
        err[name] = float(np.sqrt(np.mean((f_m / f_true - 1) ** 2)))
        assert (best.get("polish_scale") == "standard_error") == (name == "standard errors")
    print(f"\nrms f error at the windows: {err}")
    assert err["standard errors"] < err["eq. 3.9"] / 3 and err["standard errors"] < 0.01, err


# ---------------------------------------------------------------- virtual campaigns (slow)

def _campaign(folder: Path, sweeps: tuple, ring_downs: tuple, measurement: dict) -> Path:
    """The Ministack's first assembly (Table 3.2) in the virtual lab: up and down sweeps at `sweeps` (g), and a
    dwell at the resonance of each level of `ring_downs` (g), cut off into 1.2 s of free decay; then the modal
    stage's three tables in folder/modal."""
    series = [{"level_g": lv, "directions": ["up", "down"]} for lv in sweeps]
    for lv in ring_downs:
        f = float(resonance_amplitude(lv, *JOINT, M, FIRST["zeta_v"])[1])
        series.append({"level_g": lv, "test": "ringdown", "dwell_hz": [round(f, 1)], "dwell_s": 0.2,
                       "decay_s": 1.2})
    spec = {**DEFAULT_SPEC, "seed": 5, "assemblies": {"first": DEFAULT_SPEC["assemblies"]["first"]},
            "series": series, "measurement": {**DEFAULT_SPEC["measurement"], **measurement}}
    generate(spec, folder / "campaign", folder / "truth.json")
    return campaign_tables(folder)


def _calibrate_and_cover(folder: Path, modal: Path):
    """Calibrate, sample and read what the data identify; every identified quantity's 90% interval against the
    truth's value of it."""
    cal = CalibrateSettings()
    run_calibration(modal / "modal_properties.csv", "first", folder / "cal", cal, backbone_csv=modal / "backbone.csv")
    res, notes = run_posterior(modal / "modal_properties.csv", modal / "scatter.csv", folder / "cal" / "ga_best.json",
                               "first", folder / "post", cal, PosteriorSettings(),
                               backbone_csv=modal / "backbone.csv")
    best = json.loads((folder / "cal" / "ga_best.json").read_text())
    cal = cal.resolved(best)
    data = read_modal(modal / "modal_properties.csv", "first", damping=cal.damping,
                      backbone_csv=modal / "backbone.csv")
    with np.load(folder / "post" / "chain.npz") as z:
        table, _ = identified_table(z["samples"], [str(n) for n in z["sample_names"]], cal.space, data.q, data.f,
                                    data.zeta, m=cal.m, model=cal.model, viscous=cal.viscous, weight=data.weight)
    truth = json.loads((folder / "truth.json").read_text())["assemblies"]["first"]
    theta = np.array([[truth[p] for p in cal.space.names]])
    value = {qt.name: float(qt.fn(theta)[0]) for qt in quantities(data.q, m=cal.m, model=cal.model,
                                                                  viscous=cal.viscous, space=cal.space)}
    table["truth"] = table["quantity"].map(value)
    table["covers"] = (table["q05"] <= table["truth"]) & (table["truth"] <= table["q95"])
    return res, best, data, table.set_index("quantity")


@pytest.mark.slow
def test_ring_downs_alone_calibrate_and_the_posterior_covers_the_truth(tmp_path):
    """Four ring-downs (0.3, 1, 3, 10 g; 0.1% noise): 97 windows, four read-outs. Measured: 17-33 windows over
    1.8-2.3 decades each; the chain converges by the 50-tau rule; chi, zeta_v, K0, R, the dissipation and its
    exponent and the curves identified, all within their 90% intervals; Fs, KT, k and beta left to the bounds
    (every amplitude in microslip, as with sweeps to 10 g)."""
    modal = _campaign(tmp_path, (), (0.3, 1.0, 3.0, 10.0), {"noise_fraction": 1e-3, "dc_offset_g": 0.0})
    res, best, data, table = _calibrate_and_cover(tmp_path, modal)
    assert best["n_runs"] == 4 and best["n_readouts"] == pytest.approx(4) and best["n_points"] > 60
    assert res.converged
    ident = table[table["identified"]]
    assert {"chi", "zeta_v", "K0", "R", "D_ref", "dissipation_exponent"} <= set(ident.index), table
    assert ident["covers"].all(), ident[["q05", "median", "q95", "truth"]]


@pytest.mark.slow
def test_sweeps_and_ring_downs_mixed_calibrate_as_one_campaign(tmp_path):
    """Six sweeps (1, 2, 5 g up and down) and two ring-downs (0.5 and 10 g) of the default virtual lab (0.3%
    noise, ripple, distortion): eight read-outs, the ring-downs' windows two of them; the ring-downs reach below
    and above the sweeps' amplitudes. Every identified quantity within its 90% interval."""
    modal = _campaign(tmp_path, (1.0, 2.0, 5.0), (0.5, 10.0), {})
    res, best, data, table = _calibrate_and_cover(tmp_path, modal)
    assert best["n_runs"] == 8 and best["n_readouts"] == pytest.approx(8)
    w = pd.Series(data.w, index=pd.Index(data.run_id))
    rd = [r for r in w.index.unique() if "ringdown" in r]
    assert len(rd) == 2 and w[rd].sum() == pytest.approx(2.0) and (w.drop(rd) == 1.0).all()
    rows = pd.read_csv(modal / "modal_properties.csv")
    swept = rows.loc[~rows["f_res_method"].isin(["ringdown", "dwell"]), "q_in"]
    assert data.q.min() < swept.min() / 2  # the 0.5 g ring-down reads below the sweeps' amplitudes
    ident = table[table["identified"]]
    assert {"chi", "zeta_v", "K0", "R", "D_ref"} <= set(ident.index), table
    assert ident["covers"].all(), ident[["q05", "median", "q95", "truth"]]


@pytest.mark.slow
def test_a_right_model_calibrated_from_ring_downs_validates(tmp_path):
    """The base-driven Ministack's four ring-downs (0.3-10 g, 0.1% noise, nothing hidden; seed 1 of
    tests/_support/decay_campaign.py), calibrated with the default GA: the validation's E (the exact Iwan's free
    decay from the cut, read by the same estimator, each window on its own standard error) is under the verdict's
    2 at the truth (oracle: truth.json) and at the optimum. Measured 2026-11-26: truth 0.75; the optimum 1.11
    (E_f 1.30, E_zeta 0.87); polished on eq. 3.9 it was 2.84 (E_f 3.84): a 'No' for a right model."""
    from jointcal.io import read_manifest, read_run
    from jointcal.report.verdict import HOLDS_E
    from jointcal.validate import validate_runs
    from jointcal.validate.models import model_from_best
    from jointcal.validate.testkinds import as_read
    from tests._support.decay_campaign import ministack_ring_downs

    modal_dir = ministack_ring_downs(tmp_path, "none", None, seed=1)
    run_calibration(modal_dir / "modal_properties.csv", "first", tmp_path / "cal", CalibrateSettings(),
                    backbone_csv=modal_dir / "backbone.csv")
    best = json.loads((tmp_path / "cal" / "ga_best.json").read_text())
    assert best["polish_scale"] == "standard_error"
    rows = as_read(read_manifest(tmp_path / "campaign" / "manifest.csv").to_dict("records"),
                   pd.read_csv(modal_dir / "modal_properties.csv"))
    records = [read_run(tmp_path / "campaign" / r["file"], r) for r in rows]
    truth = {**json.loads((tmp_path / "truth.json").read_text())["assemblies"]["first"], "m": best["m"],
             "viscous": best["viscous"]}
    E = {name: validate_runs([model_from_best(b) for _ in rows], records, rows).error["E"]
         for name, b in (("truth", truth), ("optimum", best))}
    assert E["truth"] < HOLDS_E and E["optimum"] < HOLDS_E, E
