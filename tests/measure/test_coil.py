"""The voltage drive's coil in the sweep fit (jointcal.measure._coil): its pole, its sensitivities, its read-out."""
from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np
import pytest

from jointcal.measure._coil import coil_pole
from jointcal.measure._rotating import demodulate, passage
from jointcal.measure._sweep_problem import NP, Problem
from jointcal.measure.sweepfit import fit_swept_mode
from jointcal.units import G
from tests._support.jacobian import assert_matches_central_difference
from tests._support.lti import lsim


def _cardano(a: float, b: float, c: float) -> np.ndarray:
    """The three roots of s^3 + a s^2 + b s + c by Cardano's formula (complex cube roots)."""
    p, q = b - a * a / 3, 2 * a**3 / 27 - a * b / 3 + c
    C = (-q / 2 + np.sqrt(complex(q * q / 4 + p**3 / 27))) ** (1 / 3)
    w = np.exp(2j * np.pi / 3)
    return np.array([C * w**k - p / (3 * C * w**k) for k in range(3)]) - a / 3


@pytest.mark.parametrize("w_e_over, g_over, zeta", [(0.74, 0.3, 0.0015), (0.2, 0.05, 0.02), (1.9, 1.0, 0.01),
                                                    (0.5, 0.0, 0.03)])
def test_the_pole_is_the_closed_form_root_of_the_coupled_cubic(w_e_over, g_over, zeta):
    """coil_pole against Cardano's root of (s + w_e)(s^2 + D s + Omega^2) + g s nearest i Omega, to 1e-10."""
    om = 2 * np.pi * 2250.0
    w_e, g, d = w_e_over * om, g_over * om**2, 2 * zeta * om
    roots = _cardano(w_e + d, om**2 + d * w_e + g, w_e * om**2)
    roots = roots[roots.imag > 0]
    s = roots[np.argmin(np.abs(np.abs(roots) - om))]
    f, z = coil_pole(om**2, d, w_e, g)
    assert f == pytest.approx(abs(s) / (2 * np.pi), rel=1e-10) and z == pytest.approx(-s.real / abs(s), rel=1e-9)
    if g == 0:  # no back-EMF: the mode's own pole
        assert f == pytest.approx(om / (2 * np.pi), rel=1e-12) and z == pytest.approx(zeta, rel=1e-9)


def _voltage_chirp(f0, zeta, w_e, g, f_lo, f_hi, rate, fs, tail, over=32):
    """A linear mode driven through a coil by a unit voltage chirp, integrated apart (scipy's lsim of the
    real 3-state system, `tests._support.lti.lsim`, `over` times oversampled): (V, response acceleration in g) at fs."""
    om = 2 * np.pi * f0
    A = np.array([[0.0, 1.0, 0.0], [-om**2, -2 * zeta * om, 1.0], [0.0, -g, -w_e]])
    B = np.array([[0.0], [0.0], [w_e]])
    Cm = np.array([[-om**2, -2 * zeta * om, 1.0]])  # the acceleration
    dur = (f_hi - f_lo) / rate
    t = np.arange(int((dur + tail) * fs * over)) / (fs * over)
    ph = 2 * np.pi * (f_lo * t + 0.5 * rate * t**2)
    v = np.where(t <= dur, np.sin(ph), 0.0) * np.clip(t / 0.05, 0, 1)
    y = lsim((A, B, Cm, np.zeros((1, 1))), v, t)
    return v[::over], y[::over] / G


def _linear_rig():
    """A linear 100 Hz mode (zeta 1%) behind a coil with its corner at 0.74 of it and a back-EMF damping as
    large as the mode's own: (w_e rad/s, g 1/s^2, pole f Hz, pole zeta)."""
    om = 2 * np.pi * 100.0
    w_e = 0.74 * om
    g = 2 * 0.01 * om * (w_e**2 + om**2) / w_e
    return w_e, g, *(float(v) for v in coil_pole(om**2, 2 * 0.01 * om, w_e, g))


@functools.cache
def _linear_chirp(eta: float):
    """The linear rig's voltage chirp at `eta`, integrated once per module (read only: both chirp tests read the
    slow one and the fast one, the same records)."""
    w_e, g, f_t, z_t = _linear_rig()
    v, acc = _voltage_chirp(100.0, 0.01, w_e, g, 60.0, 140.0, eta * (f_t * z_t) ** 2, 1024.0, 1.5)
    v.flags.writeable = acc.flags.writeable = False
    return v, acc


@functools.cache
def _slow_fit():
    """The slow chirp (eta 0.5) fitted with its coil, once for the two tests that read it."""
    _, _, f_t, z_t = _linear_rig()
    return fit_swept_mode(*_linear_chirp(0.5), 1024.0, 1.01 * f_t, 1.3 * z_t, coil="fit")


def test_a_voltage_chirp_read_with_its_coil_is_the_pole_of_the_cubic():
    """The linear rig under voltage chirps: the slow one (eta 0.5) fitted with its coil gives the closed-form
    pole of the cubic within 1e-4 in f and 1% in zeta; a fast one (eta 20) read with the rig's own coil held
    gives it within 1e-4 and 1%. A coil that is not a corner and a gain is refused."""
    w_e, g, f_t, z_t = _linear_rig()
    slow = _slow_fit()
    assert slow.coil is not None
    assert slow.f_hz == pytest.approx(f_t, rel=1e-4) and slow.zeta == pytest.approx(z_t, rel=0.01)
    v, acc = _linear_chirp(20.0)
    rig = fit_swept_mode(v, acc, 1024.0, 1.01 * f_t, 1.3 * z_t, coil=(w_e, g))
    assert rig.coil == (w_e, g)
    assert rig.f_hz == pytest.approx(f_t, rel=1e-4) and rig.zeta == pytest.approx(z_t, rel=0.01)
    with pytest.raises(ValueError, match="coil"):
        fit_swept_mode(v, acc, 1024.0, f_t, z_t, coil=(-1.0, 0.0))


@pytest.mark.xfail(strict=True, reason="open: one slow sweep of a single mode fixes its coil's corner (452 rad/s "
                   "against 465) but hardly its back-EMF gain (12 against 16513 1/s^2: along the cubic's weakly "
                   "determined real root); held, that coil puts the fast chirp's pole -0.039% off")
def test_the_coil_fitted_on_a_slow_sweep_reads_a_fast_one():
    """The linear rig: the fast chirp (eta 20) read with the coil its slow chirp (eta 0.5) fitted gives the
    cubic's pole within 3e-4 in f and 3% in zeta."""
    _, _, f_t, z_t = _linear_rig()
    slow = _slow_fit()
    fast = fit_swept_mode(*_linear_chirp(20.0), 1024.0, 1.01 * f_t, 1.3 * z_t, coil=slow.coil)
    assert fast.f_hz == pytest.approx(f_t, rel=3e-4) and fast.zeta == pytest.approx(z_t, rel=0.03)


@pytest.mark.parametrize("free_start", [True, False])
def test_the_coil_sensitivities_are_the_central_difference_of_the_same_model(free_start):
    """With a coil fitted, the misfit's Jacobian by the coil kernel's forward sensitivities against a
    Richardson-extrapolated central difference of the misfit itself, column by column: the coil's two new
    directions (its corner and back-EMF gain) and every other one through the coil's third state, at an
    amplitude-dependent point, from a fitted moving start (the coil's forced start depends on it) and from rest."""
    from tests.measure.test_sweepfit import _force_chirp

    from jointcal.models import MinistackModel

    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, 1024.0, 1.0)
    cut = int(np.argmax(np.abs(acc))) - int(0.2 * 1024)
    sig = demodulate(F[cut:], acc[cut:], 1024.0, f0, zeta, 0.45, 6.0)
    W0 = 2 * np.pi * f0
    prob = Problem.build(passage(sig, 0.15, 0.02, 6.0, free_start), f0, zeta, 0.15, None, 0.01, 0.3, 0.3)
    prob = replace(prob, l_lo=-40.0, l_hi=5.0).with_coil((0.7 * W0, 0.02 * W0**2), True)
    assert prob.ps.free_start == free_start and {22, 23} <= set(prob.free_all)
    free = prob.free_all
    p = np.zeros(NP)
    p[[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 15]] = [0.004, -0.1, -0.01, -0.002, 0.1, 0.01, 1.1, 0.2, 0.4, 0.05, -0.03,
                                                   -3e-4]
    p[[11, 12, 13, 14, 16, 17, 18, 19, 20, 21, 22, 23]] = [0.02, -0.01, 0.01, 0.005, -0.01, 0.003, 0.3, -0.2, 0.1,
                                                           0.2, 0.1, 0.003]
    pf = p[free]
    assert np.abs(prob.misfit(pf, free)).max() < 10  # a point the model follows, not a diverged one
    assert_matches_central_difference(prob, pf, free)
