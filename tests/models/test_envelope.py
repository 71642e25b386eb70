"""The steady-state envelope model against analytic FRFs, energy balance and slow simulated sweeps."""
import numpy as np
import pytest
from scipy.signal import fftconvolve

from jointcal.models.envelope import _structure_terms
from jointcal.models import (
    G, Fixture, IwanParams, MinistackModel, cubic_spring, dissipation, harmonic_balance, simulate, steady_state,
)
from tests._support.lockin import linear_sweep

M = 2.65 / G
IWAN = IwanParams(313.0, 1.02e6, -0.65, 0.004)  # Table 3.2, first assembly
K, ZV = 6.12e5, 0.0015


def _analytic(f, A_g, m, ks, zeta_v, fixture=None, gain=1.0, tau=0.0):
    """Response/base of the linear model from its equations of motion, solved as a linear system."""
    w = 2 * np.pi * f
    c = 2 * zeta_v * np.sqrt(ks * m)
    T = np.empty(f.size, complex)
    for i, wi in enumerate(w):
        if fixture is None:
            Mm, Kk, Cc, Mb = np.array([[m]]), np.array([[ks]]), np.array([[c]]), np.array([m])
        else:
            mc, fc, zc = fixture
            kc = mc * (2 * np.pi * fc) ** 2
            Mm = np.array([[mc + m, m], [m, m]])
            Kk = np.diag([kc, ks])
            Cc = np.diag([2 * zc * np.sqrt(kc * mc), c])
            Mb = np.array([mc + m, m])
        X = np.linalg.solve(Kk + 1j * wi * Cc - wi**2 * Mm, -Mb * A_g * G)
        T[i] = 1.0 - wi**2 * X.sum() / (A_g * G)  # slug absolute acceleration over base
    return gain * T * np.exp(-1j * w * tau)


@pytest.mark.parametrize("fixture", [None, (4 * M, 5500.0, 0.01)])
@pytest.mark.parametrize("gain, tau", [(1.0, 0.0), (1.2, 40e-6)])
def test_linear_model_equals_the_analytic_frf(fixture, gain, tau):
    f = np.linspace(500, 6000, 400)
    fx = None if fixture is None else Fixture(*fixture)
    model = MinistackModel(m=M, k=K + IWAN.KT, zeta_v=ZV, fixture=fx, sensor_gain=gain, sensor_delay_s=tau)
    T = steady_state(model, f, 2.0).transmissibility
    ref = _analytic(f, 2.0, M, K + IWAN.KT, ZV, fixture, gain, tau)
    assert np.max(np.abs(T / ref - 1)) < 1e-12


@pytest.mark.parametrize("level", [1.0, 2.0, 5.0, 10.0])
def test_energy_balance_and_quadrature_equal_harmonic_balance(level):
    """Work of the base per cycle = dissipation; at quadrature the frequency is harmonic balance's."""
    f = np.linspace(1800, 2500, 3001)
    model = MinistackModel(m=M, k=K, zeta_v=ZV, iwan=IWAN)
    ss = steady_state(model, f, level)
    w, q, A = 2 * np.pi * f, ss.q_in, level * G
    c = 2 * ZV * np.sqrt((K + IWAN.KT) * M)
    work = np.pi * M * A * np.abs(ss.relative) * np.sin(np.angle(ss.relative))  # effective force -m a_b on z
    lost = np.pi * c * w * q**2 + dissipation(q, IWAN.Fs, IWAN.KT, IWAN.chi, IWAN.beta)
    assert np.max(np.abs(work / lost - 1)) < 1e-9
    ph = np.angle(ss.relative)
    i = np.flatnonzero((ph[:-1] - np.pi / 2) * (ph[1:] - np.pi / 2) <= 0)[0]
    fq = f[i] + (np.pi / 2 - ph[i]) / (ph[i + 1] - ph[i]) * (f[i + 1] - f[i])
    qq = np.interp(fq, f[i:i + 2], q[i:i + 2])
    f_hb, _ = harmonic_balance(qq, IWAN.Fs, IWAN.KT, IWAN.chi, IWAN.beta, K, M, ZV)
    assert abs(fq / f_hb - 1) < 2e-6  # interpolation between 0.23 Hz steps


def _sim_envelope(model, level, f_lo, f_hi, rate, fs=25600.0, cycles=40):
    """Slow up sweep simulated in time; lock-in transmissibility at the instantaneous frequency."""
    t, phase, finst, base = linear_sweep(f_lo, f_hi, rate, fs, level)
    ramp = np.clip(t / 0.05, 0, 1)
    base = base * ramp
    y = simulate(model, base, fs, omega_h=0.2).response_g  # finer than the default 0.65: a reference
    nw = int(fs * cycles / f_lo)
    win = np.hanning(nw) / np.hanning(nw).sum()  # Hann-weighted lock-in: rejects the response's harmonics
    e = np.exp(-1j * phase)
    B = fftconvolve(base * e, win, "same")
    Y = fftconvolve(y * e, win, "same")
    keep = slice(nw + int(0.1 * fs), len(t) - nw)
    return finst[keep], (Y / B)[keep]


CASES = [
    ("joint", dict(), (1.0, 2.0, 5.0, 10.0)),
    # A can whose coupled mode sits near 3x the slug's resonance (f_can = 5500 Hz: 3 x 2078 Hz at 5 g)
    # is driven by the joint's 3rd harmonic, which feeds back on the fundamental (-0.8% at 5 g,
    # -1.3% at 10 g, independent of the sweep rate): a super-harmonic interaction that no
    # first-harmonic model has. With f_can = 15 kHz the same check gives 0.34%; here 1 g at 5.5 kHz
    # (weak hysteresis harmonics) and a stiffer can at every level.
    ("fixture", dict(fixture=Fixture(4 * M, 5500.0, 0.01)), (1.0,)),
    ("fixture_8k", dict(fixture=Fixture(4 * M, 8000.0, 0.01)), (1.0, 5.0, 10.0)),
    ("cubic", dict(elements=(cubic_spring(5e11),)), (1.0, 10.0)),
]


def _away_from_fold(model, ss, f, level):
    """Frames where the softening does not steepen the response more than 2x (plus 2) beyond the
    equivalent linear system frozen at its amplitude: d ln q / d ln f stays finite away from a fold
    and diverges at one, where a sweep's transient lags furthest behind the steady state."""
    mu, gamma = _structure_terms(model, 2 * np.pi * f, (1, f.size))
    mu, gamma = mu[0], (np.ones(f.size) if gamma is None else gamma[0])
    Kz = -gamma * M * level * G / ss.relative + mu  # the joint DOF's dynamic stiffness at the solution
    frozen = np.zeros(f.size)
    i = np.arange(1, f.size - 1)
    up = np.log(np.abs(gamma[i + 1] / (Kz[i] - mu[i + 1])))
    down = np.log(np.abs(gamma[i - 1] / (Kz[i] - mu[i - 1])))
    frozen[i] = (up - down) / np.log(f[i + 1] / f[i - 1])
    slope = np.gradient(np.log(ss.q_in), np.log(f))
    return np.abs(slope) <= 2 * np.abs(frozen) + 2


@pytest.mark.parametrize("name, extra, levels", CASES, ids=[c[0] for c in CASES])
def test_matches_slow_simulated_sweeps(name, extra, levels):
    """Within 0.5% in magnitude and 0.5 deg in phase along +-4% of the peak, away from a fold.

    eta = 0.0025 at the level's smallest damping. Near a fold (here: the bent flank below the
    peak, where the response is 3x steeper than the frozen linear system) the sweep lags the
    steady state more than its linear group delay (0.9% at eta 0.01, 0.5% at 0.002): that error
    is the sweep's, it falls with eta.
    """
    model = MinistackModel(m=M, k=K, zeta_v=ZV, iwan=IWAN, **extra)
    grid = np.linspace(1500, 2600, 2201)
    for level in levels:
        fr = steady_state(model, grid, level)
        f_peak = grid[np.argmax(np.abs(fr.transmissibility))]
        zeta = 0.015 if level < 5 else 0.025
        rate = 0.0025 * (f_peak * zeta) ** 2
        f, T_sim = _sim_envelope(model, level, 0.96 * f_peak, 1.04 * f_peak, rate)
        ss = steady_state(model, f, level)
        away = _away_from_fold(model, ss, f, level)
        T = ss.transmissibility[away]
        mag = np.abs(np.abs(T_sim[away]) / np.abs(T) - 1)
        ph = np.degrees(np.abs(np.angle(T_sim[away] / T)))
        print(f"\n{name} {level:g} g: peak {f_peak:.0f} Hz, rate {rate:.1f} Hz/s, {away.mean():.0%} of the band "
              f"away from a fold: max |mag| err {mag.max() * 100:.3f}%, max phase err {ph.max():.3f} deg")
        assert away.mean() > 0.75  # the comparison covers most of the band, the fold zone is narrow
        assert mag.max() < 5e-3 and ph.max() < 0.5


def test_vectorised_over_parameter_sets_equals_one_at_a_time():
    f = np.linspace(1800, 2500, 300)
    Fs = np.array([[200.0], [313.0], [600.0]])
    batch = steady_state(MinistackModel(m=M, k=K, zeta_v=ZV, iwan=IwanParams(Fs, IWAN.KT, IWAN.chi, IWAN.beta),
                                        elements=(cubic_spring(np.array([[0.0], [5e11], [1e11]])),)), f, 5.0)
    for i, (fs_i, k3_i) in enumerate(zip(Fs[:, 0], (0.0, 5e11, 1e11))):
        one = steady_state(MinistackModel(m=M, k=K, zeta_v=ZV, iwan=IwanParams(fs_i, IWAN.KT, IWAN.chi, IWAN.beta),
                                          elements=(cubic_spring(k3_i),)), f, 5.0)
        np.testing.assert_allclose(batch.transmissibility[i], one.transmissibility, rtol=1e-12)


def test_fold_branches_follow_the_sweep_direction():
    """A model with a fold (a hardening cubic spring on a 2%-damped slug): up and down sweeps take
    different branches, each returned amplitude is a root (energy balance), and each direction flags
    one jump within 5 Hz of where a slow simulated sweep (20 Hz/s) jumps, later in the sweep direction.

    (The Iwan joints of Table 3.2's family, alone, showed a single root at every frequency when the
    fixed point was scanned on a fine log-q grid, 1 to 10 g: their damping grows with the softening.)
    """
    model = MinistackModel(m=M, k=1.63e6, zeta_v=0.02, elements=(cubic_spring(2e13),))
    f = np.linspace(2400, 3000, 2401)
    up = steady_state(model, f, 5.0, direction="up")
    down = steady_state(model, f, 5.0, direction="down")
    assert up.jump.sum() == 1 and down.jump.sum() == 1
    f_up, f_down = f[up.jump][0], f[down.jump][0]
    differ = np.abs(up.q_in / down.q_in - 1) > 1e-6
    assert f[differ].min() >= f_down - 0.5 and f[differ].max() <= f_up + 0.5  # two branches between the folds
    c = 2 * 0.02 * np.sqrt(1.63e6 * M)
    for ss in (up, down):
        w, q = 2 * np.pi * f, ss.q_in
        work = np.pi * M * 5.0 * G * np.abs(ss.relative) * np.sin(np.angle(ss.relative))
        assert np.max(np.abs(work / (np.pi * c * w * q**2) - 1)) < 1e-9
    for (fa, fb), f_model in (((2400.0, 3000.0), f_up), ((3000.0, 2400.0), f_down)):
        fs_, T = _sim_envelope(model, 5.0, fa, fb, 20.0)
        d = np.diff(np.abs(T)) / np.diff(fs_) * np.sign(fb - fa)
        f_sim = fs_[np.argmin(d)]  # the steepest fall along the sweep: the jump
        print(f"\nsweep {fa:.0f}->{fb:.0f} Hz: model jump {f_model:.1f} Hz, simulated {f_sim:.1f} Hz")
        assert 0 <= (f_sim - f_model) * np.sign(fb - fa) < 5.0


def test_irregular_frames_stay_finite_and_below_the_dashpot_bound():
    """Frames almost at one frequency with base levels jumping 10x between them (a dwell, a stepped sine)
    once threw the branch continuation's extrapolated guess to q = inf. Every amplitude is finite and
    below the closed-form bound m A / (c omega): |K_z - m omega^2| >= Im K_z >= c omega (the joint only
    adds dissipation)."""
    rng = np.random.default_rng(3)
    f = np.sort(rng.uniform(1500.0, 2700.0, 60))
    base = rng.uniform(0.5, 5.0, 60)
    k, zv = 6.12e5 * 1.1, 0.0015
    model = MinistackModel(m=M, k=k, zeta_v=zv, iwan=IwanParams(626.0, 1.02e6, -0.65, 0.004))
    for direction in ("up", "down"):
        q = steady_state(model, f, base, direction=direction).q_in
        c = 2 * zv * np.sqrt((k + 1.02e6) * M)
        assert np.all(np.isfinite(q))
        assert np.all(q <= M * base * G / (c * 2 * np.pi * f))


@pytest.mark.parametrize("chi", [-0.95, -0.5, 0.0])
@pytest.mark.parametrize("ratio", [0.05, 0.6, 1.0, 1.7, 6.0])  # q / phi_max: microslip, the onset, macroslip
def test_the_kernels_backbone_first_harmonic_is_the_cycle_integral_of_the_backbone(chi, ratio):
    """k_b = 4/(pi q) int_0^{pi/2} F_b(q cos t) cos t dt of the virgin backbone (eq. 3.2, `iwan.backbone`) by
    adaptive quadrature, and its slope d k_b / d log q by finite differences of that integral."""
    from scipy.integrate import quad

    from jointcal.models import IwanParams, backbone
    from jointcal.models._envelope_kernel import _backbone_first_harmonic
    from jointcal.models.envelope import GAUSS_NODES, GAUSS_WEIGHTS
    from jointcal.models.iwan import derived

    p = IwanParams(4.0, 204.0, chi, 0.1)
    phimax, R, _ = (float(np.asarray(v)) for v in derived(p.Fs, p.KT, p.chi, p.beta))

    def kb(q):
        lim = [np.arccos(min(phimax / q, 1.0))] if q > phimax else None
        I = quad(lambda t: float(backbone(q * np.cos(t), p)) * np.cos(t), 0.0, np.pi / 2, points=lim,
                 epsabs=0.0, epsrel=1e-13, limit=200)[0]
        return 4.0 * I / (np.pi * q)

    q = ratio * phimax
    k, dk = _backbone_first_harmonic(q, p.KT, R, chi, phimax, GAUSS_NODES, GAUSS_WEIGHTS)
    h = 1e-5
    assert k == pytest.approx(kb(q), rel=1e-7)
    if ratio == 1.0:  # the backbone's slope jumps at phi_max (beta > 0): the kernel's is the microslip side's
        slope = (3 * kb(q) - 4 * kb(q * np.exp(-h)) + kb(q * np.exp(-2 * h))) / (2 * h)
    else:
        slope = (kb(q * np.exp(h)) - kb(q * np.exp(-h))) / (2 * h)
    assert dk == pytest.approx(slope, rel=1e-5, abs=1e-6 * p.KT)
