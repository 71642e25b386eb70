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

from jointcal.report.verdict import first_answer, identified_html, verdict_items

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
