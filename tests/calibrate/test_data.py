"""The modal stage's tables read for the calibration (jointcal.calibrate.data)."""
from __future__ import annotations

import pandas as pd

from jointcal.calibrate.data import select_modal


def test_level_mistakes_are_left_out_of_the_calibration():
    """A run flagged for its units, level or channels at ingest never enters the fit."""
    modal = pd.DataFrame({"run_id": ["r1", "r2", "r3", "r4"], "assembly": "first", "q_in": [1e-4, 2e-4, 1e-3, 3e-4],
                          "f_res_hz": 2000.0, "zeta_phase_resonance": 0.01, "zeta_res": 0.01,
                          "level_g": [1.0, 1.0, 1.0, 2.0],
                          "flags": ["", "level:base_accel_g", "swapped:base_accel_g;bad_samples",
                                    "clipped:response_accel_g"]})
    data = select_modal(modal, "first")
    assert data.run_id == ("r1",)  # clipped: the peak is missing, damping biased high (see below)
