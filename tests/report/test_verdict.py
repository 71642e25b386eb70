"""The verdict's first answer agrees with every test the page shows, and no sentence contradicts another.

The cases are the ones issue 29 found on real campaigns: E within the scale next to a chi-square that
rejects (the held-out beam), E and chi-square both rejecting (UNESP mode 1), the next test asking for an
amplitude the runs already passed, and an unconverged chain listed as identifying every parameter.
"""
from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from jointcal.report.verdict import first_answer, identified_html, named_effects, verdict_html, verdict_items

BEST = {"model_kind": "modal", "excitation": "voltage"}
NOT_APPLICABLE = {"recommended": None, "reason": "This campaign is voltage-driven.", "applicable": False,
                  "what_would_identify": "Raise the voltage level in steps and read q_in from the modal stage until it "
                                         "exceeds 0.625 in.", "phi_max_interval_in": [0.55, 0.625],
                  "largest_amplitude_in": 0.9, "targets": []}
OWN = [{"x_lo": 0.0, "x_hi": 1.0, "sigma_mag_db": 0.05, "sigma_phase_deg": 0.3, "dof": 40, "source": "own noise"}]


def _identified(free=(), why=""):
    rows = [dict(quantity=p, unit="-", kind="parameter", log=True, q_in=np.nan, q05=v / 2, median=v, q95=2 * v,
                 free_share=1.0 if p in free else 0.0, identified=p not in free, fixed_directions=6.0, why_not=why)
            for p, v in (("Fs", 246.0), ("KT", 1155.0), ("chi", -0.7), ("beta", 0.2), ("k", 1.3e4), ("zeta_v", 0.002))]
    rows.append(dict(quantity="phi_max", unit="in", kind="combination", log=True, q_in=np.nan, q05=0.56, median=0.59,
                     q95=0.62, free_share=0.0, identified=True, fixed_directions=6.0, why_not=why))
    for name, v in (("f(q_min)", 18.6), ("zeta(q_min)", 0.005), ("f(q_max)", 18.4), ("zeta(q_max)", 0.008)):
        rows.append(dict(quantity=name, unit="Hz" if name[0] == "f" else "-", kind="curve", log=True,
                         q_in=0.18 if "min" in name else 0.9, q05=0.99 * v, median=v, q95=1.01 * v, free_share=0.0,
                         identified=True, fixed_directions=6.0, why_not=""))
    t = pd.DataFrame(rows)
    t["identified"] = t["identified"] & (t["why_not"] == "")  # as jointcal.posterior.identified.settled gives it
    return t


def _first_word(answer: str) -> str:
    return re.match(r"<b>(Yes|No)</b>", answer).group(1)


@pytest.mark.parametrize("E, p, word", [(0.92, 1e-80, "No"), (9.36, 2e-192, "No"), (9.0, 0.5, "No"),
                                        (0.9, 0.3, "Yes")])
def test_the_first_answer_is_yes_only_when_every_test_shown_passes(E, p, word):
    fit = {"fit_chi2": 426.0 if p < 1e-3 else 15.0, "fit_dof": 16.0, "fit_p": p, "noise_source": ("repeats", "own")}
    a1 = verdict_items(best=BEST, identified=_identified(), validation={"E": E, "scale": OWN}, fit=fit)[0][1]
    assert _first_word(a1) == word and first_answer({"E": E}, fit) is (word == "Yes")
    assert ("are rejected by" in a1) == (p < 1e-3) and ("agree with" in a1) == (p >= 1e-3)
    assert "repeated test" not in a1  # no repeats: E's scale is the runs' own noise, and the words say so
    assert "own noise" in a1 and "smooth backbone" in a1


def test_e_within_the_scale_next_to_a_rejecting_chi_square_is_no_in_every_sentence():
    """The held-out beam: 'Yes: E = 0.92 ... about as close as a repeated test' beside p = 1e-80."""
    fit = {"fit_chi2": 426.0, "fit_dof": 16.0, "fit_p": 1e-80}
    items = verdict_items(best=BEST, identified=_identified(), validation={"E": 0.92, "scale": OWN}, fit=fit,
                          next_test=NOT_APPLICABLE)
    a1, a3 = items[0][1], items[2][1]
    assert a1.startswith("<b>No</b>") and "Yes" not in a1 and "chi-square 426 for 16" in a1
    assert a1.index("rejected") < a1.index("E = ")  # the failing test is the reason given first
    assert "a model the tests of item 1 reject" in a3


def test_the_next_test_never_asks_for_an_amplitude_the_runs_already_passed():
    """UNESP mode 1: 'until q_in exceeds 0.625 in' with 0.9 in measured, two lines after 'every parameter'."""
    items = verdict_items(best=BEST, identified=_identified(), next_test=NOT_APPLICABLE,
                          validation={"E": 9.36}, fit={"fit_chi2": 906.0, "fit_dof": 6.0, "fit_p": 2e-192})
    a3, a4 = items[2][1], items[3][1]
    assert "Every parameter is identified" in a3
    assert "0.625" not in a4 and "exceeds" not in a4 and "no further level is needed" in a4
    free = verdict_items(best=BEST, identified=_identified(free=("Fs", "KT")), next_test=NOT_APPLICABLE)[3][1]
    assert "past the posterior's macroslip onset" in free and "a higher level will not identify them" in free
    below = dict(NOT_APPLICABLE, largest_amplitude_in=0.3)
    assert "exceeds 0.625 in" in verdict_items(best=BEST, identified=_identified(free=("Fs",)),
                                               next_test=below)[3][1]


def test_an_unsettled_chain_identifies_nothing_and_the_page_says_what_to_run():
    why = ("No parameter is identified from this chain alone: the posterior did not converge (8.1 of the 50 "
           "autocorrelation times posterior.tau_factor asks for); run it longer with `posterior: {max_steps: "
           "333000, stop_projected: 0}` in a config file (the chain resumes from its checkpoint).")
    t = _identified(why=why)
    items = verdict_items(best=BEST, identified=t, next_test=NOT_APPLICABLE)
    a3, a4 = items[2][1], items[3][1]
    assert "Every parameter is identified" not in a3 and "max_steps: 333000" in a3
    assert "Fs 246" not in a3  # no value of a parameter from the unsettled chain
    assert "Settle the posterior first" in a4 and "0.625" not in a4
    page = identified_html(t, title="t")
    assert "not from this chain alone" in page and "max_steps: 333000" in page and "left to the bounds" not in page


def _identified_k0():
    rows = [dict(quantity=p, unit="-", kind="parameter", log=p != "chi", q_in=np.nan, q05=v / 2, median=v, q95=2 * v,
                 free_share=0.0 if ok else 1.0, identified=ok, fixed_directions=4.0)
            for p, v, ok in (("Fs", 300.0, False), ("KT", 1e6, False), ("chi", -0.6, True), ("beta", 0.01, False),
                             ("k", 6e5, False), ("zeta_v", 0.0015, True))]
    rows.append(dict(quantity="K0", unit="lbf/in", kind="combination", log=True, q_in=np.nan, q05=1.62e6,
                     median=1.63e6, q95=1.64e6, free_share=0.0, identified=True, fixed_directions=4.0))
    return pd.DataFrame(rows)


@pytest.mark.parametrize("p, shown", [(0.13, "p = 0.13"), (0.046, "p = 0.046"), (2e-54, "p = 2e-54")])
def test_the_chi_square_p_is_printed_as_it_stands_against_the_rejection_level(p, shown):
    """Read against P_REJECT (0.05), p keeps two significant digits: the real UNESP beam's 0.13 printed as 0.1, and
    0.046 (rejected) would have printed as 0.05."""
    from jointcal.posterior.stage import P_REJECT

    (_, a1), *_ = verdict_items(best={"model_kind": "modal", "excitation": "voltage"}, identified=_identified_k0(),
                                validation=None, fit={"fit_chi2": 9.767, "fit_dof": 6.0, "fit_p": p},
                                diagnosis=None, next_test=None, corrected={})
    assert shown in a1
    assert ("are rejected by" in a1) == (p < P_REJECT)


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
    items = verdict_items(best={"model_kind": "ministack", "excitation": "base"}, identified=_identified_k0(),
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
    items = verdict_items(best={"model_kind": "modal", "excitation": "force"}, identified=_identified_k0(),
                          validation={"E": 1.3}, fit={"fit_chi2": 20.0, "fit_dof": 18.0, "fit_p": 0.33},
                          next_test={"recommended": None, "reason": "This campaign is force-driven.",
                                     "what_would_identify": "A response amplitude past macroslip."})
    a1, a2, a3, a4 = (a for _, a in items)
    assert "<b>Yes</b>" in a1 and "agree with" in a1
    assert a2 == "The discrepancy stage did not run."  # it runs for every excitation: absent only when not run
    assert "K0 = k + KT 1.63e6 [1.62e6, 1.64e6] lbf/in" in a3 and "Fs" in a3.split("Left to the bounds")[1]
    assert "No level recommended" in a4 and "force-driven" in a4


@pytest.mark.parametrize("floor, said", [(30.1, True), (0.25, False), (None, False)])
def test_an_unexplained_item_states_the_fast_models_floor_when_it_is_above_the_scatter(floor, said):
    # UNESP mode 1's chirps (eta 200-600): the fast model is E = 30 from its own time simulation, which is why
    # nothing is named there; below the repeat scatter the floor is no part of the answer
    diag = {"effect": "unexplained", "confidence": "low", "metric_before": 9.36, "metric_after": 9.15,
            "outside_library": "the 2nd-harmonic fingerprint is 1.1% of the fundamental",
            "fast_model_floor": {"E": floor}}
    items = verdict_items(best={"model_kind": "modal", "excitation": "voltage"}, identified=_identified(),
                          validation={"E": 9.36}, fit={"fit_chi2": 9.767, "fit_dof": 6.0, "fit_p": 0.13},
                          diagnosis=diag, next_test=NOT_APPLICABLE)
    a2 = items[1][1]
    assert a2.startswith("Unexplained") and "9.36" in a2
    assert ("E = 30.10 from the time simulation" in a2) is said


def test_an_unexplained_item_says_when_the_stages_refit_of_the_papers_model_alone_closes_most_of_the_gap():
    # the real dwell campaign (ring-downs): the calibration's eq. 3.9 gives E = 67.9, and the same model refit on the
    # decays' own uncertainties 10.8, with no effect named
    diag = {"effect": "unexplained", "confidence": "low", "metric_before": 67.94, "metric_after": 10.83,
            "fast_model_floor": {"E": 0.11}}
    items = verdict_items(best={"model_kind": "modal", "excitation": "voltage"}, identified=_identified(),
                          validation={"E": 67.94}, fit={"fit_chi2": 4005.0, "fit_dof": 5.0, "fit_p": 0.0},
                          diagnosis=diag, next_test=NOT_APPLICABLE)
    a2 = items[1][1]
    assert "the paper's model itself comes to E = 10.83" in a2 and "eq. 3.9" in a2
    diag["metric_after"] = 60.0
    a2 = verdict_items(best={"model_kind": "modal", "excitation": "voltage"}, identified=_identified(),
                       validation={"E": 67.94}, fit={"fit_chi2": 4005.0, "fit_dof": 5.0, "fit_p": 0.0},
                       diagnosis=diag, next_test=NOT_APPLICABLE)[1][1]
    assert "itself comes to" not in a2
