"""The objective, eq. 3.9 (jointcal.calibrate.objective): vectorised over a
population, zero on exact data, a penalty on invalid rows; QSMA's offset from the harmonic balance."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from jointcal.calibrate import PARAMS, PENALTY, CalibrateSettings, objective, predict
from jointcal.models import harmonic_balance, resonance_amplitude
from tests._support.modal_tables import LEVELS, M, TABLE_3_2, _data

FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])
SPACE = CalibrateSettings().space


def test_objective_is_eq_3_9_and_vectorised():
    d = _data()
    rng = np.random.default_rng(3)
    pop = SPACE.to_physical(rng.random((50, 6)))
    pop[0] = FIRST
    got = objective(pop, d.q, d.f, d.zeta, m=M, eta=0.7)
    f, z = harmonic_balance(d.q, *FIRST[:5], M, FIRST[5])
    by_hand = 0.7 * np.mean(((d.f - f) / d.f) ** 2) + 0.3 * np.mean(((d.zeta - z) / d.zeta) ** 2)
    assert got[0] == pytest.approx(by_hand, rel=1e-12)
    one_by_one = [objective(p[None], d.q, d.f, d.zeta, m=M, eta=0.7)[0] for p in pop]
    np.testing.assert_allclose(got, one_by_one, rtol=1e-12)


def test_objective_is_zero_on_exact_data_and_penalises_invalid_rows():
    q, f, z = resonance_amplitude(np.array(LEVELS, float), *FIRST[:5], M, FIRST[5])
    pop = np.array([FIRST, FIRST * [1, 1, np.nan, 1, 1, 1], FIRST * [1, 1, 1.6, 1, 1, 1], FIRST])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = objective(pop, q, f, z, m=M, valid=[True, True, True, False])
    assert got[0] < 1e-20  # exact data: only rounding (absolute tolerance, Gamma = 0 in exact arithmetic)
    assert got[1] == PENALTY and got[2] == PENALTY and got[3] == PENALTY  # NaN, chi < -1, flagged invalid
    assert np.all(np.isfinite(got))


def test_qsma_sits_above_harmonic_balance_as_documented():
    q = np.array([5.1e-5, 2.9e-4])  # 1 g and 10 g of Table 3.2's first assembly
    fq, _ = predict(FIRST[None], q, m=M, model="qsma")
    fh, _ = predict(FIRST[None], q, m=M, model="harmonic_balance")
    np.testing.assert_allclose(100 * (fq / fh - 1)[0], [0.15, 0.35], atol=0.03)
