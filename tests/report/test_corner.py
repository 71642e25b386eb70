"""The report's figures (jointcal.report.corner, jointcal.report.calibration): the corner
plot carries the status, the points and a colour bar; the GA's exploration figure."""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.posterior import mode_labels
from jointcal.report.calibration import exploration_figure
from jointcal.report.corner import corner_figure
from jointcal.report.summary import ga_best_point
from tests._support.samples import _bimodal

BOUNDS = CalibrateSettings().full_bounds  # the Ministack kind's defaults


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
