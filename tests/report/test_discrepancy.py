"""The discrepancy stage's figures (jointcal.report.discrepancy)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.report.discrepancy import before_after_figure


def test_the_sweeps_figure_of_a_campaign_mixing_sweeps_with_ring_downs_and_dwells_draws_the_sweeps(tmp_path):
    """A mixed campaign's validation frames hold a ring-down's window table and a dwell's steady point beside the
    sweeps' envelopes; the sweeps' before/after figure draws the sweeps and passes over the others (it stopped
    with KeyError: 'f_hz' on the virtual beam's force campaign of sweeps, a ring-down and dwells)."""
    f = np.linspace(90.0, 110.0, 50)
    sweep = pd.DataFrame({"f_hz": f, "resp_meas_g": 1.0 / (1 + (f - 100.0) ** 2),
                          "resp_sim_g": 1.0 / (1 + (f - 100.2) ** 2)})
    decay = pd.DataFrame({"q_meas_in": [1e-3, 5e-4], "f_meas_hz": [99.0, 99.5], "f_sim_hz": [99.1, 99.6],
                          "zeta_meas": [0.02, 0.018], "zeta_sim": [0.021, 0.018]})
    dwell = pd.DataFrame({"part": ["dwell"], "f_hz": [99.0], "mag_meas_db": [3.0], "mag_sim_db": [3.1]})
    d = {"assembly": "beam", "recalibrated": {"model": "neighbour_mode"}, "metric_before": 20.7, "metric_after": 0.6}
    path = tmp_path / "before_after.png"
    before_after_figure({"s": sweep, "r": decay}, {"s": sweep, "r": decay, "w": dwell}, d, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
