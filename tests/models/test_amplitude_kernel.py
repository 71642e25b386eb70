"""The numba kernel of the amplitude curves against the whole-array numpy expressions it follows
(`amplitude._harmonic_balance_numpy`, `amplitude._qsma_numpy`): equal to rounding on a grid of parameter
sets from deep microslip to past macroslip, for every broadcast the callers use, with one compiled signature."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from jointcal.calibrate import predict
from jointcal.models import G, amplitude, derived, harmonic_balance, population_curves, qsma
from jointcal.models import _amplitude_kernel

M = 2.65 / G
RTOL = 1e-12  # measured: 2.4e-14 at worst (one power per point, the quadrature summed in another order)


def _population(n: int, seed: int = 3) -> np.ndarray:
    """n parameter sets (Fs, KT, chi, beta, k, zeta_v) over the GA's range and beyond."""
    rng = np.random.default_rng(seed)
    return np.column_stack([10 ** rng.uniform(1, 3, n), 10 ** rng.uniform(5, 7, n), rng.uniform(-0.95, 0.0, n),
                            10 ** rng.uniform(-4, 0, n), 10 ** rng.uniform(5, 6.5, n), 10 ** rng.uniform(-4, -2, n)])


def _same(new, ref):
    """Equal to RTOL where the reference is finite, not finite where it is not, same shape and type."""
    for a, b in zip(new, ref):
        assert type(a) is type(b) and np.shape(a) == np.shape(b)
        finite = np.isfinite(b)
        assert np.array_equal(finite, np.isfinite(a))
        np.testing.assert_allclose(np.asarray(a)[finite], np.asarray(b)[finite], rtol=RTOL, atol=0)


@pytest.mark.parametrize("viscous", ["dashpot", "constant"])
@pytest.mark.parametrize("model", ["harmonic_balance", "qsma"])
def test_a_population_at_many_amplitudes_equals_the_numpy_expressions(model, viscous):
    theta = _population(200)
    q = np.geomspace(1e-7, 1e-2, 97)  # from deep microslip to past phi_max for most sets
    phi_max = derived(*theta[:, :4].T)[0]
    assert 0.1 < np.mean(q > phi_max[:, None]) < 0.9
    ref_fn = amplitude._harmonic_balance_numpy if model == "harmonic_balance" else amplitude._qsma_numpy
    cols = [theta[:, i:i + 1] for i in range(6)]
    with np.errstate(all="ignore"):
        ref = ref_fn(q, *cols[:5], M, cols[5], viscous=viscous)
    fn = harmonic_balance if model == "harmonic_balance" else qsma
    _same(fn(q, *cols[:5], M, cols[5], viscous=viscous), ref)
    _same(population_curves(theta, q, M, harmonic=model == "harmonic_balance", viscous=viscous), ref)
    _same(predict(theta, q, m=M, model=model, viscous=viscous), ref)  # type: ignore[arg-type]


P0 = (313.0, 1.02e6, -0.65, 0.004, 6.12e5, M, 0.0015)
BROADCASTS = {
    "scalars": (1e-5, *P0),
    "amplitudes, one set": (np.geomspace(1e-7, 1e-3, 9), *P0),
    "sets along the last axis": (np.geomspace(1e-7, 1e-3, 9)[:, None], np.array([[300.0, 200.0, 100.0]]), *P0[1:]),
    "amplitudes per set": (np.geomspace(1e-7, 1e-3, 12).reshape(3, 4), np.array([[300.0], [200.0], [50.0]]), *P0[1:]),
    "three axes": (np.geomspace(1e-7, 1e-3, 5).reshape(1, 1, 5), np.array([300.0, 100.0]).reshape(2, 1, 1),
                   1.02e6, np.array([-0.6, -0.3, 0.0]).reshape(1, 3, 1), *P0[3:]),
    "a strided read-only view": (np.broadcast_to(np.geomspace(1e-7, 1e-3, 20)[::2], (3, 10)),
                                 np.array([[300.0], [200.0], [50.0]]), *P0[1:]),
    "NaN parameters": (np.geomspace(1e-7, 1e-3, 5), np.array([[np.nan], [300.0]]), *P0[1:]),
    "no amplitudes": (np.zeros(0), *P0),
}


@pytest.mark.parametrize("case", list(BROADCASTS))
@pytest.mark.parametrize("harmonic", [True, False])
def test_every_broadcast_equals_the_numpy_expressions_with_one_signature(case, harmonic):
    args = BROADCASTS[case]
    fn, ref_fn = (harmonic_balance, amplitude._harmonic_balance_numpy) if harmonic else (qsma, amplitude._qsma_numpy)
    with np.errstate(all="ignore"):
        ref = ref_fn(*args)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no FutureWarning on broadcast views handed to numba
        _same(fn(*args), ref)
    assert len(_amplitude_kernel.curves.signatures) == 1


def test_amplitudes_must_be_positive():
    for q in (0.0, np.array([1e-5, -1e-6])):
        with pytest.raises(ValueError, match="positive displacements"):
            harmonic_balance(q, *P0)
    with pytest.raises(ValueError, match="viscous must be"):
        qsma(1e-5, *P0, viscous="linear")  # type: ignore[arg-type]
