"""validate.drive.drive_gain: the campaign's modal constant as the model is driven through it."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.validate.drive import drive_gain


def _table(level: str, a: np.ndarray, slope: np.ndarray, f: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({level: np.linspace(0.1, 1.0, a.size), "f_res_hz": f, "modal_constant_re": a.real,
                         "modal_constant_im": a.imag, "modal_slope_re": slope.real, "modal_slope_im": slope.imag})


def test_a_force_drives_through_the_magnitude_of_its_modal_constant_the_lag_is_the_channels():
    """Three force read-outs of a mode of modal mass m whose response channel lags the force by tau: each
    A = e^{-i w_r tau} / m at its own resonance. The model is driven through 1/m, real and flat."""
    m, tau = 0.00259, 4e-4
    f = np.array([99.4, 98.7, 97.6])
    a = np.exp(-2j * np.pi * f * tau) / m
    ac, da, wc = drive_gain(_table("level_lbf", a, np.zeros(3, complex), f))
    assert ac == pytest.approx(1 / m, rel=1e-12) and ac.imag == 0.0 and da == 0j
    assert wc == pytest.approx(2 * np.pi * 98.7)


def test_a_force_read_away_from_the_driving_point_keeps_its_residues_sign():
    """A response sensor away from the driving point reads the mode's real residue phi_s phi_d / m, which can be
    negative; a lagging channel turns it by -w tau. The model is driven through the residue with its sign, real and
    flat (its magnitude alone would turn the drive by 180 deg)."""
    r, tau = -0.4 / 0.00259, 4e-4
    f = np.array([99.4, 98.7, 97.6])
    ac, da, _ = drive_gain(_table("level_lbf", r * np.exp(-2j * np.pi * f * tau), np.zeros(3, complex), f))
    assert ac == pytest.approx(r, rel=1e-12) and ac.imag == 0.0 and da == 0j


def test_a_voltage_keeps_its_complex_constant_and_slope():
    """A voltage's A(w) is the coil's and the amplifier's, complex and sloped: moved to the median resonance
    along each run's slope, the medians of its parts."""
    f = np.array([99.0, 98.0, 97.0])
    slope = np.full(3, 0.5 - 2.0j)
    a = (300 - 40j) + slope * 2 * np.pi * (f - 98.0)
    ac, da, wc = drive_gain(_table("level_V", a, slope, f))
    assert ac == pytest.approx(300 - 40j) and da == pytest.approx(0.5 - 2.0j)
