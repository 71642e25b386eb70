"""The GA and its polish (jointcal.calibrate.fit) on synthetic modal tables of a known
joint: five seeds reach one optimum, the calibrated curves match the truth's, and QSMA absorbs its bias into the
parameters.

Synthetic modal tables (tests/_support/modal_tables.py) play the modal stage: the harmonic-balance resonance of a
known joint at the Table 3.1 levels, with 0.02% noise on f and 1% on zeta."""
from __future__ import annotations

import multiprocessing

import numpy as np
import pytest

from jointcal.calibrate import PARAMS, CalibrateSettings, calibrate, predict
from jointcal.models import harmonic_balance
from tests._support.modal_tables import M, TABLE_3_2, _data

FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])


# ---------------------------------------------------------------- GA runs (slow)

def _objectives_of_seed(seed: int) -> tuple[float, float]:
    cal = calibrate(_data(), CalibrateSettings.from_config({"seed": seed}))
    return cal.best["objective"], cal.best["objective_ga"]


@pytest.mark.slow
def test_five_seeds_reach_the_same_optimum():
    """(a) polished objectives of 5 seeds within 1% of the best (noisy data: the optimum is > 0).
    The seeds are independent GA runs (each single threaded): two at a time."""
    with multiprocessing.get_context("fork").Pool(2) as pool:
        out = pool.map(_objectives_of_seed, range(5))
    values, raw = np.array(out).T
    assert values.min() > 0
    assert np.all(values <= 1.01 * values.min()), values
    assert np.all(values <= raw)  # the polish never makes it worse


@pytest.mark.slow
@pytest.mark.parametrize("eta, f_tol", [(0.85, 0.15), (0.99, 0.05)])
def test_calibrated_curves_match_the_truth(eta, f_tol):
    """(b) on the GA's eq. 3.9 optimum. With eta = 0.85 (the paper) the 1% damping noise outweighs the
    0.02% frequency noise in eq. 3.9 and pulls the frequency curve off by up to ~0.1%; eta = 0.99
    meets 0.05%. (The posterior, which weights by the noise, is checked against 0.05% in posterior/test_stage.py.)"""
    d = _data()
    cal = calibrate(d, CalibrateSettings.from_config({"eta": eta}))
    theta = np.array([cal.best[p] for p in PARAMS])
    q = np.geomspace(d.q.min(), d.q.max(), 60)
    f_t, z_t = harmonic_balance(q, *FIRST[:5], M, FIRST[5])
    f_c, z_c = harmonic_balance(q, *theta[:5], M, theta[5])
    assert np.max(np.abs(f_c / f_t - 1)) < f_tol / 100
    assert np.max(np.abs(z_c / z_t - 1)) < 0.02


@pytest.mark.slow
def test_qsma_calibration_absorbs_its_bias_into_the_parameters():
    """Data from harmonic balance (what a sweep shows), fitted with QSMA (the paper's model):
    QSMA fits the data as well (to 0.01%), but with another joint. Measured: the stuck stiffness
    k + KT comes out 0.5% high, chi 0.009 lower and zeta_v 30% low; the same parameters in harmonic
    balance (what the structure does) miss the measured frequencies by -0.18% (1 g) to -0.41%
    (10 g) and the damping by +0.3% to +0.8%."""
    d = _data(noise=(1e-5, 1e-3))
    hb = calibrate(d, CalibrateSettings.from_config({"model": "harmonic_balance", "eta": 0.99}))
    qs = calibrate(d, CalibrateSettings.from_config({"model": "qsma", "eta": 0.99}))
    t_hb = np.array([hb.best[p] for p in PARAMS])
    t_qs = np.array([qs.best[p] for p in PARAMS])
    f_fit, _ = predict(t_qs[None], d.q, m=M, model="qsma")
    f_as_hb, _ = predict(t_qs[None], d.q, m=M, model="harmonic_balance")
    assert np.max(np.abs(f_fit[0] / d.f - 1)) < 0.01e-2  # QSMA mimics the data ...
    miss = 100 * (f_as_hb[0] / d.f - 1)
    assert np.all(miss < -0.15) and miss.min() < -0.35  # ... with a joint that is 0.15-0.4% too soft
    k0 = lambda t: t[1] + t[4]  # noqa: E731
    assert k0(t_hb) == pytest.approx(k0(FIRST), rel=2e-4)  # harmonic balance recovers the truth's k + KT
    assert k0(t_qs) / k0(t_hb) - 1 > 2e-3  # QSMA's is off
    assert t_hb[2] == pytest.approx(FIRST[2], abs=2e-3) and abs(t_qs[2] - t_hb[2]) > 5e-3  # chi
    assert t_hb[5] == pytest.approx(FIRST[5], rel=0.02) and t_qs[5] < 0.8 * t_hb[5]  # zeta_v absorbs the rest


# ---------------------------------------------------------------- points with their own standard errors

def test_the_polish_of_windows_with_standard_errors_is_the_validations_E_of_the_backbone():
    """Oracle: each run's mean over its windows of (r_f^2 + r_zeta^2) / 2, r the relative error over the window's
    own scale, averaged over runs (`jointcal.validate.error.envelope_error` on `compare_decay`'s r_f, r_zeta),
    written out here by hand: the polish's residuals' squared norm is it."""
    from jointcal.calibrate.data import ModalData
    from jointcal.calibrate.fit import _residuals

    rng = np.random.default_rng(3)
    q = np.concatenate([np.geomspace(1e-4, 3e-6, 12), np.geomspace(3e-5, 2e-6, 7)])
    runs = np.array(["a"] * 12 + ["b"] * 7)
    f, z = harmonic_balance(q, *FIRST[:5], M, FIRST[5])
    f, z = f * (1 + 1e-4 * rng.standard_normal(q.size)), z * (1 + 1e-2 * rng.standard_normal(q.size))
    s_f, s_z = rng.uniform(5e-5, 2e-4, q.size), rng.uniform(3e-3, 1e-2, q.size)
    w = np.where(runs == "a", 1 / 12, 1 / 7)
    data = ModalData("first", tuple(runs), np.full(q.size, np.nan), q, f, z, "zeta_res", (np.nan, np.nan), (), w,
                     (s_f, s_z), q)
    s = CalibrateSettings()
    theta = FIRST * np.array([1.1, 0.95, 1.0, 1.2, 1.02, 0.9])
    f_m, z_m = harmonic_balance(q, *theta[:5], M, theta[5])
    r_f, r_z = (f - f_m) / f / s_f, (z - z_m) / z / s_z
    E2 = np.mean([np.mean((r_f[runs == r] ** 2 + r_z[runs == r] ** 2) / 2) for r in ("a", "b")])
    assert np.sum(_residuals(theta[None], data, s, s.space) ** 2) == pytest.approx(E2, rel=1e-12)


def test_a_knee_within_the_windows_must_earn_its_place():
    """Tied optima (within chi^2(1) at 95% of the lowest): the fewest windows in macroslip wins, then the lowest;
    a knee that fits better than that keeps its place."""
    from jointcal.calibrate.fit import TIE, pick_polished

    assert TIE == pytest.approx(3.84)
    assert pick_polished([10.0, 12.0, 13.5], [1, 0, 0]) == 1
    assert pick_polished([10.0, 14.0], [1, 0]) == 0
    assert pick_polished([np.nan, 10.0, 11.0], [0, 2, 1]) == 2
