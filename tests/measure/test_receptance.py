"""The other modes' receptance from a force-referenced FRF's flanks (jointcal.measure.receptance) against the
closed-form receptance of two linear modes."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.measure.receptance import Receptance, flank_receptance
from jointcal.units import G

M, WN, ZETA = 1.0 / G, 2 * np.pi * 99.5, 0.012  # the beam's mode at the driving point
M2, W2, Z2 = 0.5 / G, 2 * np.pi * 230.0, 0.01  # its second mode


def _frf(f_hz):
    w = 2 * np.pi * f_hz
    return 1.0 / (M * (WN**2 - w**2 + 2j * ZETA * WN * w)) + 1.0 / (M2 * (W2**2 - w**2 + 2j * Z2 * W2 * w))


@pytest.mark.parametrize("f_eval", [95.0, 99.5])
def test_the_flanks_give_the_second_modes_receptance_near_the_mode(f_eval):
    f = np.linspace(0.7 * 99.5, 1.3 * 99.5, 2000)  # a sweep's band, +-30%
    rc = flank_receptance(f, _frf(f), 1.0 / M, source="s1")
    w = 2 * np.pi * f_eval
    exact = 1.0 / (M2 * (W2**2 - w**2))  # its stiffness line; the damping's share is 1e-4 of it here
    # r0 + r2 w^2 is the line's expansion to (w / w2)^2: the next term, (w / w2)^4, is 3% at the band's top; 1.4%
    # at 95-99.5 Hz, which moves the decay's zeta by 1.4% of the residual's +1% (0.014%)
    assert abs(rc.residual(f_eval) / exact - 1) < 0.02
    assert rc.modal_constant == 1.0 / M and rc.source == "s1"
    # no residual fitted (A given, one mode): the second mode's 4.5e-4 in/lbf, missed, is not zero
    assert Receptance(1.0 / M).residual(f_eval) == 0.0


def test_a_band_that_does_not_pass_the_mode_is_said():
    f = np.linspace(60.0, 98.0, 500)  # stops at the peak: no flank above it
    with pytest.raises(ValueError, match="sweep further past the mode"):
        flank_receptance(f, _frf(f), 1.0 / M)
    with pytest.raises(ValueError, match="nonzero modal constant"):
        flank_receptance(f, _frf(f), 0.0)
