"""Report pieces: mode detection with a known answer, chain status lines, Table 3.2 in HTML, the verdict, stamped
figures."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.posterior import mode_labels
from jointcal.report.calibration import exploration_figure
from jointcal.report.corner import corner_figure
from jointcal.report.modal import steady_frames
from jointcal.report.summary import bound_hits, chain_status, ga_best_point, landing_html
from jointcal.report.table_3_2 import table_3_2_html
from jointcal.report.verdict import named_effects, verdict_html, verdict_items
from tests._support.samples import _bimodal

BOUNDS = CalibrateSettings().full_bounds  # the Ministack kind's defaults


def test_chain_status_states_the_tau_multiple_and_why_it_stopped():
    hist = np.array([[1000, 100, 90], [2000, 150, 140], [6000, 586, 500]], dtype=float)
    ok, line = chain_status(dict(tau_history=hist, converged=False, stop_reason="projected", projected_steps=62160.0))
    assert not ok and line.startswith("NOT converged: 10.2 tau of the 50 required") and "62160 steps" in line
    ok, line = chain_status(dict(tau_history=np.array([[14000, 270, 200]], float), converged=True,
                                 stop_reason="converged", projected_steps=14000.0))
    assert ok and line.startswith("converged: 14000 steps = 51.9 tau")


def _table(zeta_v=1e-4):
    rows = []
    for p in PARAMS:
        v = {"Fs": 36.6, "KT": 5.1e5, "chi": -0.65, "beta": 0.135, "k": 1e6, "zeta_v": zeta_v}[p]
        rows.append(dict(assembly="first", param=p, unit="-", ga_optimum=v, posterior_median=v,
                         posterior_q05=v / 2 if p != "chi" else v - 0.01, posterior_q95=v * 2 if p != "chi" else v + 0.01,
                         width_ratio=0.8 if p == "beta" else 0.1, constrained=p != "beta"))
    return pd.DataFrame(rows)


def test_table_3_2_html_gives_no_value_the_posterior_does_not_support():
    history = pd.DataFrame({"generation": [0, 1], "objective": [3.0, 2.0], "Fs": [10.0, 42.1], "KT": [1e5, 4.6e5],
                            "chi": [-0.5, -0.59], "beta": [0.1, 0.0013], "k": [1e5, 9.97e5], "zeta_v": [0.01, 0.0019]})
    ga = ga_best_point(history)
    assert ga["Fs"] == 42.1 and ga["objective"] == 2.0
    modes = pd.DataFrame([dict(mode=k, weight=w, param=p, median=m, q05=m, q95=m) for k, (w, m) in
                          enumerate([(0.87, 1561.0), (0.13, 37.3)]) for p in PARAMS])
    identified = pd.DataFrame({"quantity": PARAMS, "identified": [False, True, True, False, False, True]})
    html = table_3_2_html(_table(), {"first": ga}, {"first": modes}, BOUNDS, identified={"first": identified})
    assert html.count("<tr>") == 1 + 5  # header, posterior, two modes, polished optimum, GA best
    assert html.count("not identified") == 3  # Fs, beta, k: in the posterior row, and no value in any other
    for value in ("36.6", "42.1", "0.135", "0.0013", "9.97e5", "1e6"):  # Fs, beta, k values, in no row
        assert f">{value}<" not in html and f">{value} " not in html, value
    assert "5.1e5<br><small>[2.55e5, 1.02e6]</small>" in html  # KT identified: median and 90% interval
    assert "spans 18.3 to 73.2 (bounds)" in html  # the range the bounds leave Fs, not a value
    # the GA's points as members: the GA best's chi -0.59 and zeta_v 0.0019 lie outside their intervals, its KT
    # 4.6e5 inside; the polished optimum sits at the medians here
    assert html.count("outside the 90% interval") == 2 and ">4.6e5<" in html
    assert "touches lower bound" in html and "class=\"bound\"" in html  # zeta_v's interval reaches 1e-4
    assert "(between modes)" in html and "mode 2 (13% of the draws)" in html
    assert bound_hits({p: v for p, v in zip(PARAMS, [36.6, 5.1e5, -0.65, 0.135, 1e6, 1e-4])}, BOUNDS) == {
        "zeta_v": "lower"}
    page = landing_html(runs=pd.DataFrame({"run_id": ["a", "b"], "flags": ["", "clipped; snr"]}),
                        modal=pd.DataFrame({"run_id": ["a", "b"], "flags": ["", "unusable"]}),
                        status={"first": (False, "NOT converged: 10.2 tau")}, notes={"first": ["MULTIMODAL (2 modes)"]},
                        verdict="<ol><li>the verdict</li></ol>")
    assert page.index("the verdict") < page.index("Run flags")
    assert "<b>1</b> of 2 runs (clipped: 1; snr: 1)" in page and "NOT converged: 10.2 tau" in page


def test_figures_carry_the_status_points_and_a_colour_bar():
    x, _ = _bimodal(n=4000)
    png = corner_figure(x[:, :3], ["a", "b", "c"], points={"GA best": [0.0, 0.0, 0.5], "polished optimum": [6, 0, 0.5]},
                        bounds=([-5, -5, 0], [10, 5, 1]), modes=mode_labels(x[:, :3]),
                        stamp=("NOT converged: 10.2 tau", False))
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    rng = np.random.default_rng(0)
    h = pd.DataFrame({p: 10 ** rng.uniform(*np.log10(BOUNDS[p]), 300) if p != "chi" else rng.uniform(-0.95, 0, 300)
                      for p in PARAMS})
    h.insert(0, "objective", 10 ** rng.uniform(-5, 1, 300))
    h.insert(0, "generation", 0)
    best = ga_best_point(h)
    png = exploration_figure(h, title="t", ga_best=best, polished=best, bounds=BOUNDS)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_ramps_are_trimmed_from_the_envelopes():
    n = 200
    ref = np.r_[np.linspace(0.1, 1.0, 20), np.ones(n - 40), np.linspace(1.0, 0.1, 20)]  # start and stop ramps
    env = pd.DataFrame({"drive_on": True, "ref_re": ref, "ref_im": 0.0})
    keep = steady_frames(env).to_numpy()
    assert keep[20:n - 20].all()  # the steady sweep is kept
    assert not keep[:18].any() and not keep[-18:].any()  # ramp frames below 95% of the level are dropped


def _identified():
    rows = [dict(quantity=p, unit="-", kind="parameter", log=p != "chi", q_in=np.nan, q05=v / 2, median=v, q95=2 * v,
                 free_share=0.0 if ok else 1.0, identified=ok, fixed_directions=4.0)
            for p, v, ok in (("Fs", 300.0, False), ("KT", 1e6, False), ("chi", -0.6, True), ("beta", 0.01, False),
                             ("k", 6e5, False), ("zeta_v", 0.0015, True))]
    rows.append(dict(quantity="K0", unit="lbf/in", kind="combination", log=True, q_in=np.nan, q05=1.62e6,
                     median=1.63e6, q95=1.64e6, free_share=0.0, identified=True, fixed_directions=4.0))
    return pd.DataFrame(rows)


@pytest.mark.parametrize("newer", [False, True])
def test_verdict_answers_in_order_and_reads_either_form_of_the_diagnosis(newer):
    diag = {"effect": "fixture_flexibility", "confidence": "high", "metric_before": 17.13, "metric_after": 0.41,
            "recalibrated": {"joint_parameters": {p: {"value": v, "interval_90": sorted([0.9 * v, 1.1 * v])} for p, v in
                                                  (("Fs", 75.7), ("KT", 6.5e5), ("chi", -0.637), ("beta", 0.076),
                                                   ("k", 8.9e5), ("zeta_v", 0.00176))},
                             "effect_parameters": {"f_can_hz": {"value": 5617.0, "unit": "Hz",
                                                                "interval_90": [5602.0, 5624.0]}}}}
    if newer:
        diag["effects"] = ["fixture_flexibility"]
    nxt = {"recommended": {"level_g": 100.0, "direction": "up", "sweep_rate_hz_per_s": 1200.0, "duration_s": 1.5},
           "targets": ["Fs", "KT/k"], "share_of_draws_identifying_targets": 0.16, "identifies_targets": False,
           "confidence": 0.9, "max_level_g": 100.0, "width_now": {"Fs": 1.59, "KT/k": 2.3},
           "predicted_width_ratio_if_identified": {"Fs": 18.3, "KT/k": 14.6},
           "predicted_width_ratio": {"Fs": 1.6, "KT/k": 1.4}}
    corrected = {"Fs": False, "KT": False, "chi": True, "beta": False, "k": False, "zeta_v": True}
    items = verdict_items(best={"model_kind": "ministack", "excitation": "base"}, identified=_identified(),
                          validation={"E": 17.13}, fit={"fit_chi2": 306.7, "fit_dof": 18.0, "fit_p": 2e-54},
                          diagnosis=diag, next_test=nxt, corrected=corrected)
    (q1, a1), (q2, a2), (q3, a3), (q4, a4) = items
    assert "reproduce" in q1 and "<b>No</b>" in a1 and "17.13" in a1 and "p = 2e-54" in a1
    assert "fixture_flexibility" in a2 and "<b>17.13</b> to <b>0.41</b>" in a2 and "5617" in a2
    assert "chi -0.637 [-0.701, -0.573]" in a3 and "zeta_v 0.00176" in a3
    assert "75.7" not in a3 and "6.5e5" not in a3 and "8.9e5" not in a3  # free directions: no value
    assert "Left to the bounds (no value is given): Fs, KT, beta, k" in a3
    assert "100 g base sweep, up, at 1200 Hz/s" in a4 and "16%" in a4 and "width ratio 18.3" in a4
    page = verdict_html({"first": items})
    assert page.index("reproduce") < page.index("discrepancy") < page.index("identify") < page.index("next test")
    assert named_effects({"effect": "none"}) == [] and named_effects({"effects": ["a", "b"], "effect": "a+b"}) == ["a", "b"]


def test_verdict_without_a_named_effect_reports_the_paper_models_identified_quantities():
    items = verdict_items(best={"model_kind": "modal", "excitation": "force"}, identified=_identified(),
                          validation={"E": 1.3}, fit={"fit_chi2": 20.0, "fit_dof": 18.0, "fit_p": 0.33},
                          next_test={"recommended": None, "reason": "This campaign is force-driven.",
                                     "what_would_identify": "A response amplitude past macroslip."})
    a1, a2, a3, a4 = (a for _, a in items)
    assert "<b>Yes</b>" in a1 and "agree with" in a1
    assert a2 == "The discrepancy stage did not run."  # it runs for every excitation: absent only when not run
    assert "K0 = k + KT 1.63e6 [1.62e6, 1.64e6] lbf/in" in a3 and "Fs" in a3.split("Left to the bounds")[1]
    assert "No level recommended" in a4 and "force-driven" in a4


def test_the_summary_says_which_runs_each_mode_has_and_which_modes_are_calibrated():
    from jointcal.report.summary import modes_html

    modal = pd.DataFrame({"run_id": ["w1", "w1", "w2", "w2", "u1", "n1"], "assembly": "beam",
                          "mode": ["m18", "m95", "m18", "m95", "m95", ""], "level_V": [0.1, 0.1, 0.3, 0.3, 0.1, 0.2],
                          "f_res_hz": [18.6, 95.1, 18.4, 94.0, 95.2, np.nan], "flags": ["", "", "", "unusable", "", "no_mode"]})
    page = modes_html(modal)
    assert "beam m18 (18.4-18.6 Hz): 2 runs (w1, w2); calibrated" in page
    # m95's usable runs hold one level (0.1 V): read, named, not calibrated, and the page says why
    assert "beam m95" in page and "3 runs (w1, w2, u1); not calibrated: read in usable runs at fewer than two levels" in page
    assert "read at no mode" in page and "n1" in page
