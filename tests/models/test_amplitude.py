"""QSMA and first-harmonic balance against limits, closed forms and the exact loop."""
import numpy as np
import pytest

from jointcal.models import G, IwanParams, derived, dissipation, force_history, harmonic_balance, qsma
from jointcal.models import resonance_amplitude

M = 2.65 / G
FIRST = dict(Fs=313.0, KT=1.02e6, chi=-0.65, beta=0.004, k=6.12e5, m=M, zeta_v=0.0015)
REASSEMBLY = dict(Fs=274.0, KT=0.90e6, chi=-0.61, beta=0.025, k=8.56e5, m=M, zeta_v=0.0017)
ODD = dict(Fs=40.0, KT=3e5, chi=-0.2, beta=0.8, k=1e5, m=M, zeta_v=0.01)
CASES = [FIRST, REASSEMBLY, ODD]


def _phi_max(P):
    return float(derived(P["Fs"], P["KT"], P["chi"], P["beta"])[0])


@pytest.mark.parametrize("P", CASES)
@pytest.mark.parametrize("model", [qsma, harmonic_balance])
def test_small_and_large_amplitude_limits(P, model):
    f0 = np.sqrt((P["k"] + P["KT"]) / P["m"]) / (2 * np.pi)
    f_macro = np.sqrt(P["k"] / P["m"]) / (2 * np.pi)
    pm = _phi_max(P)
    q = np.array([1e-8, 1e-10, 1e-12]) * pm
    f, _ = model(q, **P)
    gap = 1 - f / f0
    assert np.all(gap > 0) and gap[-1] < 1e-3
    # the softening vanishes as q**(chi+1): the microslip law of the power-law density
    np.testing.assert_allclose(gap[1:] / gap[:-1], 100.0 ** -(P["chi"] + 1), rtol=2e-3)
    f_big, _ = model(1e4 * pm, **P)
    assert f_big == pytest.approx(f_macro, rel=2e-3)
    assert f_big > f_macro


@pytest.mark.parametrize("P", CASES)
def test_qsma_microslip_damping_to_softening_ratio(P):
    """(zeta - zeta_v)/(1 - omega/omega_0) -> 4(chi+1)/(pi(chi+3)) as q -> 0 (0.1896 at chi=-0.65)."""
    f0 = np.sqrt((P["k"] + P["KT"]) / P["m"]) / (2 * np.pi)
    q = 1e-13 * _phi_max(P)
    f, z = qsma(q, **P)
    ratio = (z - P["zeta_v"]) / (1 - f / f0)
    chi = P["chi"]
    assert ratio == pytest.approx(4 * (chi + 1) / (np.pi * (chi + 3)), rel=1e-3)
    if chi == -0.65:
        assert 4 * (chi + 1) / (np.pi * (chi + 3)) == pytest.approx(0.1896, abs=1e-4)


def _first_harmonic_of_exact_loop(q, P, n=20000):
    """In-phase stiffness and loop area of the exact Masing loop under u = q cos(theta)."""
    p = IwanParams(P["Fs"], P["KT"], P["chi"], P["beta"])
    theta = np.linspace(0, 2 * np.pi, n + 1)
    u = np.r_[np.linspace(0, q, 200), q * np.cos(theta), q * np.cos(theta[1:])]
    F, _ = force_history(u, p)
    Fc = F[200 + n + 1:]
    uc = q * np.cos(theta[1:])
    k_in = 2 * np.mean(Fc * np.cos(theta[1:])) / q
    D = np.trapezoid(np.r_[F[200 + n], Fc], np.r_[q, uc])
    return k_in, D


@pytest.mark.parametrize("P", CASES)
@pytest.mark.parametrize("frac", [0.01, 0.3, 0.95, 1.5, 4.0])
def test_harmonic_balance_equals_fourier_projection_of_exact_loop(P, frac):
    q = frac * _phi_max(P)
    k_in, D = _first_harmonic_of_exact_loop(q, P)
    f, z = harmonic_balance(q, **P, viscous="constant")
    k_df = (2 * np.pi * f) ** 2 * P["m"]
    assert k_df - P["k"] == pytest.approx(k_in, rel=2e-6)
    assert D == pytest.approx(dissipation(q, P["Fs"], P["KT"], P["chi"], P["beta"]), rel=1e-5)
    assert z - P["zeta_v"] == pytest.approx(D / (2 * np.pi * k_df * q**2), rel=1e-5)


def test_vectorised_over_population_and_amplitudes():
    rng = np.random.default_rng(3)
    P = {k: np.asarray(v) for k, v in FIRST.items()}
    pop = {k: (v * rng.uniform(0.8, 1.2, (50, 1)) if k in ("Fs", "KT", "k") else v) for k, v in P.items()}
    q = np.geomspace(1e-6, 1e-3, 30)
    f, z = harmonic_balance(q, **pop)
    assert f.shape == z.shape == (50, 30)
    i = 17
    f1, z1 = harmonic_balance(q, **{k: (v[i, 0] if np.ndim(v) else v) for k, v in pop.items()})
    np.testing.assert_allclose(f[i], f1, rtol=1e-13)
    np.testing.assert_allclose(z[i], z1, rtol=1e-13)


@pytest.mark.parametrize("level", [1.0, 2.0, 5.0, 10.0])
def test_qsma_offset_from_harmonic_balance_table_3_2(level):
    """QSMA's secant frequency sits above the first-harmonic one (docs/physics.md, section 2: ~0.15% at 1 g, ~0.35% at 10 g)."""
    q, f, z = resonance_amplitude(level, **FIRST)
    assert 2 * (2 * np.pi * f) ** 2 * z * q == pytest.approx(level * G, rel=1e-9)  # energy balance
    fq, zq = qsma(q, **FIRST)
    off = fq / f - 1
    lo, hi = {1.0: (0.0012, 0.0022), 2.0: (0.0015, 0.0028), 5.0: (0.0022, 0.0035), 10.0: (0.0030, 0.0045)}[level]
    assert lo < off < hi
    if level == 1.0:
        assert q == pytest.approx(5e-5, rel=0.05) and f == pytest.approx(2254, rel=1e-3)
        assert z == pytest.approx(0.019, rel=0.03)
    if level == 10.0:
        assert q == pytest.approx(2.9e-4, rel=0.03) and f == pytest.approx(2071, rel=1e-3)


def test_bad_amplitude_rejected():
    with pytest.raises(ValueError, match="positive displacements"):
        harmonic_balance(np.array([1e-5, 0.0]), **FIRST)
