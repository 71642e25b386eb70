"""The test helper `tests._support.lti.lsim` (the linear oracle of the coil, clipping and units tests) against
`scipy.signal.lsim` itself, on short records."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from tests._support.lti import lsim

OM = 2 * np.pi * 100.0
COIL = (np.array([[0.0, 1.0, 0.0], [-OM**2, -0.02 * OM, 1.0], [0.0, -0.02 * OM * 0.74 * OM, -0.74 * OM]]),
        np.array([[0.0], [0.0], [0.74 * OM]]), np.array([[-OM**2, -0.02 * OM, 1.0]]), np.zeros((1, 1)))
SDOF = signal.StateSpace([[0.0, 1.0], [-OM**2, -0.04 * OM]], [[0.0], [-1.0]], [[-OM**2, -0.04 * OM]], [[0.0]])
LOWPASS = ([1.0], [1 / OM**2, 0.02 / OM, 1.0])


@pytest.mark.parametrize("system", [COIL, SDOF, LOWPASS], ids=["coil", "sdof", "transfer function"])
def test_the_helper_is_scipys_lsim(system):
    t = np.arange(20000) / 5000.0
    u = np.sin(2 * np.pi * (50 * t + 10 * t**2)) * np.clip(t / 0.05, 0, 1) + 0.1
    want = signal.lsim(system, u, t, interp=True)[1]
    assert np.max(np.abs(lsim(system, u, t) - want)) < 1e-8 * np.max(np.abs(want))
    with pytest.raises(ValueError, match="equally spaced"):
        lsim(system, u, t**1.01)
