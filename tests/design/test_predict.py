"""Each candidate's read-out (jointcal.design.predict): the phase-resonance energy balance
against closed forms, and macroslip said when passed."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.design import readout
from jointcal.models import derived, harmonic_balance, resonance_amplitude
from tests._support.microslip import M, PARAMS, TRUTH


@pytest.mark.parametrize("level", [1.0, 10.0, 100.0])
@pytest.mark.parametrize("direction", ["up", "down"])
def test_readout_is_the_phase_resonance_energy_balance_and_says_when_macroslip_is_passed(level, direction):
    theta = np.array([[TRUTH[p] for p in PARAMS]])
    r = readout(theta, level, direction, m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    q, f, z = resonance_amplitude(level, *theta[0, :5], M, theta[0, 5])
    assert bool(r["reached"].iloc[0])
    assert r["q_in"].iloc[0] == pytest.approx(float(q), rel=1e-9)
    f_hb, z_hb = harmonic_balance(float(q), *theta[0, :5], M, theta[0, 5])
    assert r["f_hz"].iloc[0] == pytest.approx(float(f_hb), rel=1e-9) and r["zeta"].iloc[0] == pytest.approx(float(z_hb))
    # energy balance at quadrature: the base's work pi m a q equals the dissipation 2 pi m omega^2 zeta q^2
    assert 2 * (2 * np.pi * r["f_hz"].iloc[0]) ** 2 * r["zeta"].iloc[0] * q == pytest.approx(level * 386.089, rel=1e-6)
    phi_max = derived(*theta[0, :4])[0]  # eq. 3.7
    assert bool(r["macroslip"].iloc[0]) == bool(q > phi_max) == (level == 100.0)
    # the envelope's peak: at least the phase-resonance response |a_b - omega^2 Z| / g
    assert r["peak_g"].iloc[0] >= 0.98 * np.hypot(level, (2 * np.pi * f_hb) ** 2 * q / 386.089)
