"""The modal report's envelopes (jointcal.report.modal): the drive's ramps trimmed."""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.report.modal import steady_frames


def test_ramps_are_trimmed_from_the_envelopes():
    n = 200
    ref = np.r_[np.linspace(0.1, 1.0, 20), np.ones(n - 40), np.linspace(1.0, 0.1, 20)]  # start and stop ramps
    env = pd.DataFrame({"drive_on": True, "ref_re": ref, "ref_im": 0.0})
    keep = steady_frames(env).to_numpy()
    assert keep[20:n - 20].all()  # the steady sweep is kept
    assert not keep[:18].any() and not keep[-18:].any()  # ramp frames below 95% of the level are dropped
