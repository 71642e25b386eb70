"""A joint that softens more than Masing allows for its damping (jointcal.synth.non_masing), and the verdict on it.

Truths: the Iwan dissipation per cycle in closed form (jointcal.models.dissipation, eqs. 3.3-3.5) and its
first-harmonic stiffness (jointcal.models.harmonic_balance); the virgin backbone (eq. 3.2). Acceptance: a
force-driven jointed beam whose joint gives s = 0.7 of its force to the elastic spring along its own
backbone (its softening kept, 30% of its dissipation) is calibrated, validated and judged with the default
config; the verdict's first answer must be No, from the chi-square it shows, while the same campaign of a
Masing joint (s = 0) is not rejected by its chi-square.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from jointcal.models import G, IwanParams, MinistackModel, backbone, dissipation, harmonic_balance, integrate
from jointcal.models import state_space
from jointcal.posterior.fit import P_REJECT
from jointcal.synth.non_masing import blended_force, equivalent, first_harmonic, with_share

P = IwanParams(4.0, 204.0, -0.5, 0.1)  # the jointed beam of tests/_support/rigs.py: phi_max 0.0498 in
BEAM = {"k": 818.0, "Fs": 4.0, "KT": 204.0, "chi": -0.5, "beta": 0.1, "zeta_v": 0.008, "weight_lbf": 1.0}
SHAKER = {"armature_weight_lbf": 0.05, "suspension_hz": 15.0, "bl_lbf_per_A": 0.5, "coil_ohm": 2.0, "coil_mH": 0.3}
CONFIG = Path(__file__).parents[2] / "workflow" / "config" / "config.yaml"


@pytest.mark.parametrize("s", [0.0, 0.3, 0.7])
@pytest.mark.parametrize("q", [1e-3, 8e-3, 0.08])  # microslip and past macroslip
def test_the_share_scales_the_dissipation_per_cycle_by_one_minus_s_exactly(s, q):
    k1, D = first_harmonic(q, P, s)
    assert D == pytest.approx((1 - s) * float(dissipation(q, P.Fs, P.KT, P.chi, P.beta)), rel=2e-5)
    if s == 0.0:  # the Iwan joint itself: its first harmonic is the harmonic balance's
        m, k = 1 / G, 818.0
        f, _ = harmonic_balance(q, P.Fs, P.KT, P.chi, P.beta, k, m, 0.0)
        assert k1 == pytest.approx(m * (2 * np.pi * float(f)) ** 2 - k, rel=1e-8)


def test_the_backbone_is_unchanged_and_the_softening_kept():
    z = np.linspace(0.0, 0.08, 2001)  # a monotonic loading from rest follows the backbone whatever s
    for s in (0.3, 0.7):
        assert np.allclose(blended_force(z, P, s), backbone(z, P), rtol=1e-12, atol=1e-12)
    model = MinistackModel(m=1 / G, k=818.0, zeta_v=0.0, iwan=P)
    (f0, z0), (f1, z1) = (equivalent(with_share(model, s), 1e-5) for s in (0.0, 0.7))
    (fa, za), (fb, zb) = (equivalent(with_share(model, s), 8e-3) for s in (0.0, 0.7))
    assert (f1 - fb) / (f0 - fa) > 0.9  # 70% of the force elastic keeps > 90% of the frequency drop ...
    assert zb / za == pytest.approx(0.3, rel=0.05)  # ... with 30% of the joint's damping


def test_the_time_simulation_applies_the_blended_force():
    """The integrator's nonlinear force (an output channel of r_nl) along its own joint displacement is
    (1 - s) F_iwan(history) + s F_b(z) - KT z, the force law evaluated apart."""
    fs = 20000.0
    t = np.arange(0.0, 0.6, 1 / fs)
    u = 3.0 * G * np.sin(2 * np.pi * np.cumsum(100 * (0.9 + 0.3 * t)) / fs)
    model = with_share(MinistackModel(m=1 / G, k=818.0, zeta_v=0.008, iwan=P), 0.7)
    ss = state_space(model)
    Y, z = integrate(ss, u, fs, 4, iwan=model.iwan, elements=model.elements,
                     outputs=[(np.zeros(ss.A.shape[0]), 0.0, 1.0)])
    F = blended_force(z, P, 0.7)
    assert np.abs(z).max() > 0.01
    assert np.abs(Y[0] - (F - P.KT * z)).max() < 5e-4 * np.abs(F).max()  # tips between samples: sampled history


def _verdict(folder: Path, s: float):
    """Generate the campaign, then modal read-out, calibration, the chi-square at the optimum, validation and
    the verdict's first item, each with the default config (the workflow's stages through their functions)."""
    from jointcal.calibrate import CalibrateSettings, run_calibration
    from jointcal.io import read_manifest, read_run, write_csv_atomic
    from jointcal.measure.modal import measure_run
    from jointcal.measure.scatter import scatter
    from jointcal.posterior import PosteriorSettings
    from jointcal.posterior.stage import fit_test, posterior_of
    from jointcal.report.verdict import first_answer, verdict_items
    from jointcal.synth import generate
    from jointcal.validate import ValidateSettings, validate_runs
    from jointcal.validate.models import run_models
    from jointcal.validate.runs import drive_gain

    cfg = yaml.safe_load(CONFIG.read_text())
    camp, work = folder / "campaign", folder / "work"
    spec = {"seed": 1, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": 0.01},
            "sweep": {"f_start_hz": 70.0, "f_stop_hz": 130.0, "rate_hz_per_s": 20.0, "ramp_s": 0.05, "tail_s": 1.5},
            "series": [{"level_V": v, "directions": ["up"]} for v in (0.05, 0.1, 0.2, 0.4, 0.8, 1.6)],
            "assemblies": {"beam": {**BEAM, "backbone_share": s}}, "rig": {"reference": "force", "shaker": SHAKER}}
    generate(spec, camp, folder / "truth.json")
    rows = read_manifest(camp / "manifest.csv").to_dict("records")
    records = [read_run(camp / r["file"], r) for r in rows]
    table = pd.DataFrame([{**{k: r[k] for k in ("run_id", "assembly", "sequence", "direction")},
                           **measure_run(rec, r, modal_kw=cfg["modal"])[2]} for r, rec in zip(rows, records)])
    write_csv_atomic(table, work / "modal_properties.csv")
    write_csv_atomic(scatter(table), work / "scatter.csv")
    cal, ps = CalibrateSettings.from_config(cfg["calibrate"]), PosteriorSettings.from_config(cfg["posterior"])
    run_calibration(work / "modal_properties.csv", "beam", work / "calibration", cal)
    lp, best, _, theta, _, sources = posterior_of(work / "modal_properties.csv", work / "scatter.csv",
                                                  work / "calibration" / "ga_best.json", "beam", cal, ps)
    fit = fit_test(lp, theta) | {"noise_source": sources}
    models, _ = run_models(best, table.set_index("run_id")["f_res_hz"].to_dict(), [r["run_id"] for r in rows])
    gain = drive_gain(table)
    v = validate_runs(models, records, [{**r, "drive_gain": gain} for r in rows],
                      settings=ValidateSettings.from_config(cfg.get("validate")), envelopes_kw=cfg["envelopes"],
                      modal_kw=cfg["modal"])
    identified = pd.DataFrame(columns=["quantity", "unit", "kind", "log", "q_in", "q05", "median", "q95",
                                       "free_share", "identified"])
    a1 = verdict_items(best=best, identified=identified, validation=v.error, fit=fit)[0][1]
    print(f"\ns = {s}: {a1}")
    return first_answer(v.error, fit), fit, a1


@pytest.mark.slow
def test_a_joint_softening_more_than_masing_allows_gets_a_no_and_a_masing_joint_does_not(tmp_path):
    answer, fit, a1 = _verdict(tmp_path / "non_masing", 0.7)
    assert answer is False and a1.startswith("<b>No</b>")
    assert fit["noise_source"] == ("own", "own")  # no repeats: the read-outs' own scatter, not the floor
    assert fit["fit_p"] < P_REJECT and "are rejected by" in a1  # the No comes from the chi-square it shows
    answer, fit, a1 = _verdict(tmp_path / "masing", 0.0)
    assert fit["fit_p"] >= P_REJECT and "agree with" in a1 and "are rejected by" not in a1


@pytest.mark.parametrize("s", [0.3, 0.7])
@pytest.mark.parametrize("q", [1e-3, 8e-3, 0.03, 0.08])  # microslip, near and past macroslip (phi_max 0.0498 in)
def test_the_envelope_model_has_the_blended_joints_describing_function(s, q):
    """The envelope kernel's describing function of the backbone share (1 - s) K_iwan + s k_b, read back from a
    steady state on a rigid base, (K_z - m w^2) Z = -m A, against the force law integrated over a cycle."""
    from jointcal.models import steady_state
    from jointcal.models.elements import backbone_share

    m, k = 1 / G, 818.0
    model = MinistackModel(m=m, k=k, zeta_v=0.0, iwan=P, elements=(backbone_share(s),))
    k1, D = first_harmonic(q, P, s, n=20000)
    f = np.sqrt((k + k1) / m) / (2 * np.pi) * 0.9  # below resonance: one stable branch
    A = q * abs(k + k1 - m * (2 * np.pi * f) ** 2) / m / G  # base amplitude (g) that gives about q there
    st = steady_state(model, [f], A)
    qq, Z = float(st.q_in[0]), complex(st.relative[0])
    Kz = m * (2 * np.pi * f) ** 2 - m * A * G / Z
    k1q, Dq = first_harmonic(qq, P, s, n=20000)
    assert Kz.real - k == pytest.approx(k1q, rel=2e-4)
    assert Kz.imag == pytest.approx(Dq / (np.pi * qq**2), rel=2e-4)
