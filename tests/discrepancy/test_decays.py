"""The discrepancy stage from ring-downs (jointcal.discrepancy.decays, decay_stage): the points and their scatter
against a known noise, the effects a decay cannot show, and virtual ring-down campaigns of the jointed beam
(the exact Iwan time simulation with a hidden library effect, or none) where the stage names what was hidden."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate.ga import GAOptions
from jointcal.calibrate.space import PARAMS, ParamSpace
from jointcal.discrepancy import DiscrepancySettings, diagnosis_markdown
from jointcal.discrepancy.decay_stage import NOT_SEEN, not_seen
from jointcal.discrepancy.decays import DecayObjective, decay_folds, decay_runs
from jointcal.discrepancy.fit import candidate
from jointcal.effects import library
from jointcal.models import IwanParams, MinistackModel
from jointcal.models.free_decay import free_backbone
from jointcal.report.discrepancy import decay_before_after_figure, decay_residual_figure
from tests._support.decay_campaign import calibrate_and_diagnose, ring_down_campaign

JOINT = dict(Fs=4.0, KT=204.0, chi=-0.5, beta=0.1, k=818.0, zeta_v=0.008)
M = 1.0 / 386.089
SIGMA_F, SIGMA_Z = 2e-4, 0.01  # relative noise of the synthetic read-outs
BOUNDS = {"Fs": [0.1, 100.0], "KT": [10.0, 2000.0], "chi": [-0.95, 0.0], "beta": [1e-4, 5.0], "k": [10.0, 2000.0],
          "zeta_v": [1e-4, 0.1]}


def _points(seed=0, n=40):
    """Three ring-downs' windows on the truth's backbone with relative noise SIGMA_F, SIGMA_Z (backbone.csv rows),
    and their manifest rows."""
    rng = np.random.default_rng(seed)
    model = MinistackModel(m=M, k=JOINT["k"], zeta_v=JOINT["zeta_v"],
                           iwan=IwanParams(*(JOINT[p] for p in ("Fs", "KT", "chi", "beta"))))
    rows, pts = [], []
    for i, top in enumerate((7e-4, 2e-3, 5e-3)):
        q = np.geomspace(top, top / 12, n)
        f, z = free_backbone(model, q)
        rid = f"rd{i}"
        rows.append({"run_id": rid, "sequence": i + 1, "level_V": [0.1, 0.4, 1.2][i], "test": "ringdown"})
        pts.append(pd.DataFrame({"run_id": rid, "mode": "m100", "test": "ringdown", "q_in": q,
                                 "f_hz": f * (1 + SIGMA_F * rng.standard_normal(n)),
                                 "zeta": z * (1 + SIGMA_Z * rng.standard_normal(n))}))
    return pd.concat(pts, ignore_index=True), rows


def test_the_points_scaled_by_their_own_scatter_give_e_one_at_the_truth():
    backbone, rows = _points()
    runs = decay_runs(backbone, pd.DataFrame(rows), rows)
    assert len(runs) == 3 and decay_folds(runs) == {"0.1 V": [0], "0.4 V": [1], "1.2 V": [2]}
    # the scatter about a quadratic in log q per run, pooled: measured 1.98e-4 and 0.0106 (truth 2e-4, 0.01)
    assert abs(runs[0].sigma_f[0] / SIGMA_F - 1) < 0.15 and abs(runs[0].sigma_zeta[0] / SIGMA_Z - 1) < 0.15
    c = candidate("baseline", ParamSpace.from_bounds(BOUNDS), M)
    theta = np.array([JOINT[p] for p in PARAMS])
    obj = DecayObjective(c, runs)
    assert abs(obj.E(theta) - 1.0) < 0.15  # RMS of unit-variance errors; measured 0.98
    # zeta_v 10% high: measured E 5.6 (the damping's scatter is 1%); KT 1% high: 3.4 (the frequency's 2e-4)
    assert obj.E(theta * np.array([1, 1, 1, 1, 1, 1.1])) > 4 and obj.E(theta * np.array([1, 1.01, 1, 1, 1, 1])) > 2.5
    f, z = obj.predict(theta, 0)
    assert f.shape == runs[0].q_in.shape and obj.residuals(np.stack([theta, theta])).shape == (2, 2 * 3 * 40)


def test_an_effect_a_decay_cannot_show_is_not_tried_and_said_so():
    backbone, rows = _points(n=10)
    runs = decay_runs(backbone, pd.DataFrame(rows), rows)
    space = ParamSpace.from_bounds(BOUNDS)
    theta = np.array([JOINT[p] for p in PARAMS])
    scales = {"K0": JOINT["k"] + JOINT["KT"], "f0": 100.0, "q": 5e-3}
    blind = not_seen(library("modal"), space, M, scales, runs, theta)
    assert blind == {"channel_delay": NOT_SEEN, "neighbour_mode": NOT_SEEN}  # joint_settling: seen along the runs
    blind = not_seen(library("ministack"), space, M, None, runs, theta)
    assert set(blind) == {"channel_delay", "fixture_flexibility"} and "one-DOF backbone" in blind["fixture_flexibility"]


CASES = [("none", {}), ("cubic_stiffening", {"k3": 1e6}), ("elastic_softening", {"loss_ratio": 0.3})]


@pytest.mark.slow
@pytest.mark.parametrize("effect, params", CASES, ids=[c[0] for c in CASES])
def test_ring_downs_alone_name_the_hidden_effect(tmp_path, effect, params):
    """Three ring-downs (steady amplitudes 1e-3, 3e-3, 8e-3 in, 0.5% noise) of the voltage-driven beam, the effect
    hidden in the exact time simulation; calibrated from them alone (a shorter GA), then diagnosed. Measured
    (seed 1, default GA and stage settings, tests/benchmarks/accept_discrepancy_decays.py): none -> none, high
    (E 0.82 -> 0.82); cubic_stiffening -> named, high, E 14.3 -> 1.3; elastic_softening -> named, high,
    E 7.8 -> 1.1. About 12 s of CPU each (70-140 s of
    wall time on the loaded 2-core machine)."""
    ring_down_campaign(tmp_path, effect, params, seed=1)
    res = calibrate_and_diagnose(tmp_path, DiscrepancySettings(ga_generations=10, posterior_steps=200),
                                 ga=GAOptions(population=80, offspring=80, generations=40))
    d = res["diagnosis"]
    truth = json.loads((tmp_path / "truth.json").read_text())["effect"]
    assert truth["name"] == effect and d["data"] == "decays"
    assert set(d["not_seen_by_decays"]) == {"channel_delay", "neighbour_mode"}
    assert d["fast_model_floor"]["E"] < 0.5  # the linearised fast model against the time simulation at the folds
    assert d["effect"] == effect and d["confidence"] == "high", d["rule_applied"]
    if effect == "none":
        assert d["metric_after"] < 1.5
    else:
        assert d["metric_after"] <= 0.3 * d["metric_before"]  # E falls by 70% or more
        name, value = next(iter(params.items()))
        got = d["recalibrated"]["effect_parameters"][name]["value"]
        # per unit modal mass: the rig's mode (beam and armature, 1.05 lbf) for the cubic spring
        want = value / (1.05 / 386.089) if name == "k3" else value
        assert abs(got / want - 1) < 0.2, (got, want)
    md = diagnosis_markdown(d)  # the words, and the figures of a ring-down campaign
    assert "Not tried: `channel_delay`" in md and (effect in md if effect != "none" else "**No missing effect" in md)
    decay_residual_figure(res["residuals"], d, tmp_path / "res.png")
    decay_before_after_figure({}, res["validation_after"].frames, d, tmp_path / "ba.png")
    assert (tmp_path / "res.png").stat().st_size > 1000 and (tmp_path / "ba.png").stat().st_size > 1000


def test_a_levels_dwells_count_once_by_their_phase_resonance():
    backbone, rows = _points(n=10)
    dwells = [{"run_id": f"d{i}", "sequence": 4 + i, "level_V": 0.8, "test": "dwell", "dwell_hz": 95.0 + i,
               "q_dwell_quad_in": 3e-3, "f_dwell_quad_hz": 96.2, "zeta_dwell_quad": 0.016} for i in range(3)]
    own = backbone[backbone["run_id"] == "rd1"].assign(run_id="d1")  # the middle dwell's record rings down too
    runs = decay_runs(pd.concat([backbone, own]), pd.DataFrame(rows + dwells), rows + dwells)
    ids = [r.run_id for r in runs]
    assert ids == ["rd0", "rd1", "rd2", "d0:phase_resonance", "d1"]  # the level's point once, d1's own windows
    point = runs[3]
    assert (point.q_in[0], point.f_hz[0], point.zeta[0]) == (3e-3, 96.2, 0.016) and point.level == 0.8
    assert set(decay_folds(runs)) == {"0.1 V", "0.4 V", "0.8 V", "1.2 V"}


# the calibration of ring-downs alone (the workflow's default GA, `run_calibration` with `CalibrateSettings(
# model_kind="auto")`) on the Ministack campaign below, seed 1, recorded 2026-11-26: the Iwan made to follow a
# hardening backbone, its macroslip knee at the top amplitude read, where the 10 g ring-down's f and zeta change
# within a window; and the GA's other valleys (`valley_starts` of its history), which the stage starts from too
MINISTACK_CAL = dict(Fs=51.05469552418473, KT=846324.6704471813, chi=-0.64886877486747, beta=1.0111903920237635,
                     k=785383.0226586895, zeta_v=0.0015150601283350656)
MINISTACK_VALLEYS = [[19.189550948428632, 492209.348549847, -0.6217043954025752, 0.19474422371647918,
                      1124455.5704548704, 0.0019290002833395],
                     [9.732298449843723, 424201.14703244576, -0.6328512962693904, 0.23087081080497632,
                      1131775.5695216756, 0.0021915502649257],
                     [468.60848536527703, 1676659.2582781133, -0.4618160432418799, 0.001207610421073494,
                      15672.92263245624, 0.0015055717702366776]]


@pytest.mark.slow
def test_the_ministack_ring_downs_read_like_for_like_name_a_hidden_cubic_spring(tmp_path):
    """The base-driven Ministack's four ring-downs (0.3-10 g) with a cubic spring hidden (k3 2e12 lbf/in^3). The
    decay objective linearised at the calibrated model (its read-out factor, `decay_readout`) gives that model's
    validation E of the decays exactly (oracle: `validate_runs`, the time simulation read by the same estimator);
    the backbone alone gives 4.4 where the validation reads 19.7 (before the factor, the stage's floor was 11-20 and
    it said 'unexplained'). Scored on held-out runs from the calibration and its other valleys, as the stage
    starts them, the cubic spring closes the baseline's excess and finds k3 near the truth. Measured 2026-11-26:
    E 19.67 (both), held-out scores baseline 3.68, cubic 0.83, k3 2.00e12. About 20 s."""
    from jointcal.calibrate import CalibrateSettings
    from jointcal.discrepancy.decay_stage import read_again
    from jointcal.discrepancy.select import score_candidates
    from jointcal.io import read_manifest, read_run
    from jointcal.validate import validate_runs
    from jointcal.validate.testkinds import as_read
    from tests._support.decay_campaign import ministack_ring_downs

    modal_dir = ministack_ring_downs(tmp_path, "cubic_stiffening", {"k3": 2e12}, seed=1)
    modal = pd.read_csv(modal_dir / "modal_properties.csv")
    rows = as_read(read_manifest(tmp_path / "campaign" / "manifest.csv").to_dict("records"), modal)
    records = [read_run(tmp_path / "campaign" / r["file"], r) for r in rows]
    runs = decay_runs(pd.read_csv(modal_dir / "backbone.csv"), modal, rows, se=read_again(records, rows),
                      records={r["run_id"]: rec for rec, r in zip(records, rows)})
    bounds = {"Fs": [1.0, 1e4], "KT": [1e4, 1e8], "chi": [-0.95, 0.0], "beta": [1e-4, 5.0], "k": [1e4, 1e8],
              "zeta_v": [1e-4, 0.1]}  # the calibration's (ga_best.json)
    best = {**MINISTACK_CAL, "m": 0.006863702410584088, "model_kind": "ministack", "bounds": bounds}
    space = CalibrateSettings().resolved(best).space
    theta0 = np.array([best[p] for p in PARAMS])
    c0 = candidate("baseline", space, best["m"])
    E_val = validate_runs([c0.grown.model(theta0, best["m"]) for _ in rows], records, rows).error["E"]
    lin = DecayObjective(c0, runs).at(theta0)
    assert abs(lin.E(theta0) / E_val - 1) < 1e-6, (lin.E(theta0), E_val)  # like for like
    assert abs(DecayObjective(c0, runs).E(theta0) / E_val - 1) > 0.5  # the backbone alone is not
    cands = [c0, candidate("cubic_stiffening", space, best["m"])]
    valleys = [theta0, *map(np.asarray, MINISTACK_VALLEYS)]  # as `decay_stage.diagnose_decays` starts them
    scored = score_candidates(cands, runs, theta0, max_nfev=40, objective=DecayObjective, folds=decay_folds(runs),
                              starts={c.name: valleys for c in cands})
    base, cubic = scored
    assert cubic.name == "cubic_stiffening" and cubic.score <= 2.0 and cubic.score <= 0.3 * base.score, \
        (base.score, cubic.score)
    k3 = cubic.fit.theta[candidate("cubic_stiffening", space, best["m"]).grown.index("k3")]
    assert abs(k3 / 2e12 - 1) < 0.25, k3
