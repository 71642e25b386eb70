"""The report's summary page (jointcal.report.summary): chain status lines, and which runs
each mode has and which modes are calibrated."""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.report.summary import chain_status


def test_chain_status_states_the_tau_multiple_and_why_it_stopped():
    hist = np.array([[1000, 100, 90], [2000, 150, 140], [6000, 586, 500]], dtype=float)
    ok, line = chain_status(dict(tau_history=hist, converged=False, stop_reason="projected", projected_steps=62160.0))
    assert not ok and line.startswith("NOT converged: 10.2 tau of the 50 required") and "62160 steps" in line
    ok, line = chain_status(dict(tau_history=np.array([[14000, 270, 200]], float), converged=True,
                                 stop_reason="converged", projected_steps=14000.0))
    assert ok and line.startswith("converged: 14000 steps = 51.9 tau")


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
