"""Swept-sine integrator: exact propagator, linear FRFs, slow sweeps vs harmonic balance."""
import numpy as np
import pytest
from scipy.integrate import quad_vec

from jointcal.models import (
    G, Fixture, IwanParams, MinistackModel, contact_spring, harmonic_balance, qsma, resonance_amplitude, simulate,
)
from jointcal.models.simulate import fractional_delay, hermite_propagator
from jointcal.models.sliders import slider_set
from jointcal.models.structure import state_space
from tests._support.lockin import demodulate, linear_sweep, quadrature

M = 2.65 / G
TABLE_3_2 = MinistackModel(m=M, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(313, 1.02e6, -0.65, 0.004))
P = dict(Fs=313.0, KT=1.02e6, chi=-0.65, beta=0.004, k=6.12e5, m=M, zeta_v=0.0015)


def test_hermite_propagator_matches_quadrature():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(4, 4)) * 1e3
    b = rng.normal(size=4)
    h = 1e-4
    Phi, Gm = hermite_propagator(A, b, h)
    c = rng.normal(size=4)  # p(0), h p'(0), p(h), h p'(h)
    tau = lambda s: s / h
    p = lambda s: (c[0] * (1 - 3 * tau(s) ** 2 + 2 * tau(s) ** 3) + c[1] * (tau(s) - 2 * tau(s) ** 2 + tau(s) ** 3)
                   + c[2] * (3 * tau(s) ** 2 - 2 * tau(s) ** 3) + c[3] * (tau(s) ** 3 - tau(s) ** 2))
    from scipy.linalg import expm
    ref = quad_vec(lambda s: expm(A * (h - s)) @ b * p(s), 0, h, epsabs=0, epsrel=1e-12)[0]
    np.testing.assert_allclose(Gm @ c, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())
    np.testing.assert_allclose(Phi, expm(A * h), rtol=1e-12)


def _analytic_transmissibility(model, f):
    """Slug absolute acceleration over base acceleration from the 1- or 2-DOF matrices."""
    w = 2 * np.pi * f
    ss = state_space(model)
    n = ss.A.shape[0]
    X = np.linalg.solve(1j * w * np.eye(n) - ss.A, ss.bu)
    return ss.cy @ X + ss.dyu


def _steady_ratio(model, f, fs, seconds=0.6):
    t = np.arange(int(fs * seconds)) / fs
    a = np.sin(2 * np.pi * f * t) * np.minimum(1, t / 0.05)
    y = simulate(model, a, fs).response_g
    sl = slice(len(t) // 2, None)
    e = np.exp(-2j * np.pi * f * t[sl])
    return np.mean(y[sl] * e) / np.mean(a[sl] * e)


@pytest.mark.parametrize("f", [800.0, 2000.0, 2350.0, 2500.0])
@pytest.mark.parametrize("fixture", [None, Fixture(m_can=0.004, f_can=4000.0, zeta_can=0.02)])
def test_linear_model_reproduces_analytic_transmissibility(f, fixture):
    model = MinistackModel(m=M, k=1.6e6, zeta_v=0.02, fixture=fixture)
    H = _steady_ratio(model, f, 25600.0)
    T = _analytic_transmissibility(model, f)
    assert abs(H / T - 1) < 1e-3
    if fixture is None:  # and the textbook SDOF form
        c = 2 * 0.02 * np.sqrt(1.6e6 * M)
        w = 2 * np.pi * f
        assert H == pytest.approx((1.6e6 + 1j * c * w) / (1.6e6 - M * w**2 + 1j * c * w), rel=1e-3)


def test_free_vibration_frequency_is_exact():
    """Linear natural frequency error well below 0.02% even at 10 samples per cycle."""
    model = MinistackModel(m=M, k=1.6e6, zeta_v=0.001)
    fs = 25600.0
    t = np.arange(int(fs * 1.0)) / fs
    a = np.where(t < 2e-4, 1.0, 0.0) * np.sin(np.pi * t / 2e-4)  # a short bump, then free decay
    z = simulate(model, a, fs).z_in[100:]
    tz = t[100:]
    i = np.where((z[:-1] < 0) & (z[1:] >= 0))[0]
    tc = tz[i] - z[i] * (tz[i + 1] - tz[i]) / (z[i + 1] - z[i])
    f_meas = (len(tc) - 1) / (tc[-1] - tc[0])
    wn = np.sqrt(1.6e6 / M)
    f_d = wn * np.sqrt(1 - 0.001**2) / (2 * np.pi)
    assert abs(f_meas / f_d - 1) < 2e-5


def test_reduces_to_rigid_fixture_when_can_is_stiff():
    fs = 25600.0
    _, _, _, a = linear_sweep(2000, 2400, 400, fs, 2.0)
    rigid = simulate(TABLE_3_2, a, fs).response_g
    stiff = MinistackModel(m=M, k=6.12e5, zeta_v=0.0015, iwan=TABLE_3_2.iwan,
                           fixture=Fixture(m_can=0.01, f_can=4e5, zeta_can=0.01))
    y = simulate(stiff, a, fs, n_sub=1).response_g
    assert np.max(np.abs(y - rigid)) < 2e-3 * np.max(np.abs(rigid))


@pytest.mark.parametrize("level", [1.0, 2.0, 5.0, 10.0])
def test_slow_sweep_quadrature_matches_harmonic_balance(level):
    """eta = (df/dt)/(f zeta)^2 = 0.05; z in quadrature with the base acceleration."""
    q0, f0, z0 = resonance_amplitude(level, **P)
    fs = 25600.0
    rate = 0.05 * (f0 * z0) ** 2
    for fa, fb in [(0.95 * f0, 1.04 * f0), (1.04 * f0, 0.95 * f0)]:
        t, phase, finst, a = linear_sweep(fa, fb, rate, fs, level)
        sim = simulate(TABLE_3_2, a, fs)
        f_res, q, a_amp = quadrature(a, sim.z_in, phase, finst, fs, f0)
        f_hb, z_hb = harmonic_balance(q, **P)
        f_qsma, _ = qsma(q, **P)
        zeta_pr = a_amp * G / (2 * (2 * np.pi * f_res) ** 2 * q)
        print(f"{level:g} g {'up' if fb > fa else 'down'}: f={f_res:.2f} Hz, HB {f_hb:.2f} "
              f"({(f_res / f_hb - 1) * 100:+.4f}%), QSMA offset {(f_qsma / f_hb - 1) * 100:+.3f}%, "
              f"zeta {zeta_pr:.5f} vs HB {z_hb:.5f}")
        assert abs(f_res / f_hb - 1) < 5e-4
        assert abs(zeta_pr / z_hb - 1) < 0.02
        assert q == pytest.approx(q0, rel=0.02)


def test_sliders_in_the_same_integrator_converge_to_exact_joint():
    fs = 25600.0
    _, _, _, a = linear_sweep(2000, 2300, 1500, fs, 5.0)
    exact = simulate(TABLE_3_2, a, fs, n_sub=4).response_g
    errs = [np.max(np.abs(simulate(TABLE_3_2, a, fs, n_sub=4, sliders=slider_set(TABLE_3_2.iwan, n)).response_g
                          - exact)) for n in (30, 300, 3000)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 2e-4 * np.max(np.abs(exact))


def test_energy_balance_per_cycle_at_steady_state():
    """Work done by the base's effective force equals joint + dashpot dissipation."""
    fs = 51200.0
    f = 2150.0
    t = np.arange(int(fs * 0.5)) / fs
    a = 5.0 * np.sin(2 * np.pi * f * t)
    z = simulate(TABLE_3_2, a, fs).z_in
    n_per = fs / f
    i0 = len(t) - int(round(20 * n_per))
    zs, as_ = z[i0:], a[i0:] * G
    zd = np.gradient(zs, 1 / fs)
    work = -M * np.trapezoid(as_ * zd, dx=1 / fs)  # effective force -m a_base on z
    from jointcal.models import dissipation
    Z = demodulate(zs, 2 * np.pi * f * t[i0:], len(zs))[len(zs) // 2]
    q = abs(Z)
    c = 2 * 0.0015 * np.sqrt((6.12e5 + 1.02e6) * M)
    cycles = (len(zs) - 1) / n_per
    D = cycles * (dissipation(q, 313.0, 1.02e6, -0.65, 0.004) + np.pi * c * 2 * np.pi * f * q**2)
    assert work == pytest.approx(D, rel=0.01)


def test_sensor_delay_and_gain():
    fs = 25600.0
    t = np.arange(8192) / fs
    x = np.sin(2 * np.pi * 1000 * t)
    y = fractional_delay(x, 37.3e-6, fs)
    sl = slice(1000, 7000)
    assert np.max(np.abs(y[sl] - np.sin(2 * np.pi * 1000 * (t[sl] - 37.3e-6)))) < 1e-5  # edge leakage of a truncated record
    model = MinistackModel(m=M, k=1.6e6, zeta_v=0.02, sensor_gain=1.1)
    ref = simulate(MinistackModel(m=M, k=1.6e6, zeta_v=0.02), x, fs).response_g
    np.testing.assert_allclose(simulate(model, x, fs).response_g, 1.1 * ref, rtol=1e-12)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="NaN"):
        simulate(TABLE_3_2, np.array([0.0, np.nan, 1.0]), 25600.0)
    with pytest.raises(ValueError, match="zeta_v"):
        MinistackModel(m=M, k=1e6, zeta_v=-0.1)


@pytest.mark.parametrize("gap", [0.0, 2e-5])
def test_unilateral_contact_free_vibration_matches_piecewise_closed_form(gap):
    """Undamped slug on k with a contact spring kc beyond a gap: the free vibration is piecewise
    harmonic. Below the gap z = A sin(w1 t) (A the measured negative peak); beyond it an oscillation
    of frequency w2 = sqrt((k + kc)/m) about z_e = kc gap/(k + kc), entered at speed w1 sqrt(A^2 - gap^2).
    Period, positive peak (energy: 1/2 k A^2 = 1/2 k z+^2 + 1/2 kc (z+ - gap)^2) and no drift of the
    peaks over ~700 cycles are checked against that closed form."""
    k, kc, fs = 6e5, 6e5, 25600.0
    model = MinistackModel(m=M, k=k, zeta_v=0.0, elements=(contact_spring(kc, gap),))
    t = np.arange(int(fs * 0.5)) / fs
    a = 50.0 * np.where(t < 2e-4, 1.0, 0.0) * np.sin(np.pi * t / 2e-4)  # a bump, then free vibration
    z = simulate(model, a, fs).z_in[100:]
    tz = t[100:]
    A = -z.min()
    w1, w2 = np.sqrt(k / M), np.sqrt((k + kc) / M)
    ze = kc * gap / (k + kc)
    B = np.hypot(gap - ze, w1 * np.sqrt(A**2 - gap**2) / w2)
    period = (np.pi + 2 * np.arcsin(gap / A)) / w1 + (np.pi - 2 * np.arcsin((gap - ze) / B)) / w2
    i = np.where((z[:-1] < 0) & (z[1:] >= 0))[0]
    tc = tz[i] - z[i] * (tz[i + 1] - tz[i]) / (z[i + 1] - z[i])
    assert abs((tc[-1] - tc[0]) / (len(tc) - 1) / period - 1) < 1e-5
    assert abs(z.max() / (ze + B) - 1) < 2e-3  # the best-placed sample of ~700 peaks
    n = int(fs * 0.02)
    assert abs(z[-n:].max() / z[:n].max() - 1) < 2e-3 and abs(z[-n:].min() / z[:n].min() - 1) < 2e-3


def test_contact_has_no_steady_state_model():
    """The first-harmonic envelope model refuses a contact rather than silently ignoring it."""
    from jointcal.models import steady_state
    with pytest.raises(ValueError, match="unilateral contact"):
        steady_state(MinistackModel(m=M, k=6e5, zeta_v=0.001, elements=(contact_spring(1e5),)), [1000.0, 1100.0], 1.0,
                     direction="up")
    with pytest.raises(ValueError, match="contact spring"):
        MinistackModel(m=M, k=6e5, zeta_v=0.001, elements=(contact_spring(-1.0),))
