"""What the data identify (jointcal.posterior.identified), against draws along the microslip null manifold
built by hand from eqs. 3.5 and 3.7 (tests/_support/microslip.py), and against read-outs past macroslip."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.calibrate import CalibrateSettings
from jointcal.posterior.identified import fisher, fixed_directions, free_share, identified_at, identified_table
from tests._support.microslip import M, PARAMS, TRUTH, model_readouts, null_draws, readouts

SPACE = CalibrateSettings().space
NAMES = [*PARAMS, "sigma_f", "sigma_zeta"]
COMBINATIONS = {"K0", "R", "D_ref", "dissipation_exponent", "chi", "zeta_v"}
LEFT = {"Fs", "KT", "k", "beta", "KT/k", "phi_max"}


def test_draws_along_the_null_manifold_fit_the_read_outs_exactly():
    q, f, z = readouts()
    S = null_draws(q_max=q.max())
    fm, zm = model_readouts(S, q)
    assert len(S) > 300 and np.max(np.abs(fm / f - 1)) < 1e-12 and np.max(np.abs(zm / z - 1)) < 1e-12
    # ... while the parameters themselves range widely
    assert np.log10(S[:, 0].max() / S[:, 0].min()) > 1.0 and np.log10(S[:, 4].max() / S[:, 4].min()) > 1.0


def test_microslip_read_outs_fix_four_directions_and_the_combinations_not_the_parameters():
    q, f, z = readouts()
    S = null_draws(q_max=q.max())
    table, info = identified_table(S, NAMES, SPACE, q, f, z, m=M)
    t = table.set_index("quantity")
    assert set(t.index[t["identified"]]) == COMBINATIONS | set(t.index[t["kind"] == "curve"])
    assert set(t.index[~t["identified"]]) == LEFT
    assert (t["fixed_directions"] == 4).all()
    # the Fisher information is flat along the hand-built manifold: its null directions hold the manifold's tangents
    assert np.all(np.sort(np.linalg.eigvalsh(info), axis=1)[:, :2] < 1e-6 * info.trace(axis1=1, axis2=2)[:, None])
    # the identified quantities' intervals hold the truth (the manifold keeps them at the truth's values)
    for name, value in (("chi", TRUTH["chi"]), ("K0", TRUTH["KT"] + TRUTH["k"]), ("zeta_v", TRUTH["zeta_v"])):
        assert t.loc[name, "q05"] == pytest.approx(value, rel=1e-9) and t.loc[name, "q95"] == pytest.approx(value, rel=1e-9)


def test_read_outs_past_macroslip_identify_the_slip_force_and_the_split():
    q, f, z = readouts(levels=(1, 2, 5, 10, 50, 70, 100))  # q/phi_max up to 1.65 (eq. 3.7)
    rng = np.random.default_rng(3)
    theta = np.array([TRUTH[p] for p in PARAMS])
    u = SPACE.to_unit(theta) + 2e-3 * rng.standard_normal((300, 6))  # a small cloud around the truth
    S = np.column_stack([SPACE.to_physical(u), np.full((300, 2), [1e-4, 0.01])])
    t = identified_table(S, NAMES, SPACE, q, f, z, m=M)[0].set_index("quantity")
    assert {"Fs", "KT", "k", "KT/k", "phi_max", "K0", "chi"} <= set(t.index[t["identified"]])
    assert (t["fixed_directions"] >= 5).all()


def test_free_share_splits_a_gradient_along_fixed_and_free_directions():
    info = np.diag([1e8, 0.0])[None]  # the data fix direction 1 and say nothing about direction 2
    cov = np.eye(2) / 12
    assert free_share(np.array([[1.0, 0.0]]), info, cov)[0] == pytest.approx(0.0, abs=1e-12)
    assert free_share(np.array([[0.0, 1.0]]), info, cov)[0] == pytest.approx(1.0)
    # along both: variance 1/12 along the free one against 1/(1e8 + 12) along the fixed one
    assert free_share(np.array([[1.0, 1.0]]), info, cov)[0] == pytest.approx((1 / 12) / (1 / 12 + 1 / (1e8 + 12)))
    assert fixed_directions(info)[0] == 1


def test_fisher_is_that_of_the_relative_residuals_over_the_noise():
    """One read-out, one parameter moved: F_ii = (d f~/du_i / (f sigma_f))^2 + (d zeta~/du_i / (zeta sigma_z))^2."""
    q, f, z = readouts(levels=(5,))
    theta = np.array([[TRUTH[p] for p in PARAMS]])
    F = fisher(theta, [[1e-3, 0.02]], q, f, z, SPACE, m=M)[0]
    i, h = PARAMS.index("chi"), 1e-5
    u = SPACE.to_unit(theta)
    up = u.copy()
    up[0, i] += h
    f1, z1 = model_readouts(SPACE.to_physical(up), q)
    expected = ((f1[0, 0] - f[0]) / h / (f[0] * 1e-3)) ** 2 + ((z1[0, 0] - z[0]) / h / (z[0] * 0.02)) ** 2
    assert F[i, i] == pytest.approx(expected, rel=1e-3)


def test_identified_at_a_point_sees_the_microslip_null_directions():
    q, _, _ = readouts()
    theta = [TRUTH[p] for p in PARAMS]
    got = identified_at(theta, (3e-4, 0.004), q, SPACE, m=M)
    assert got == {"Fs": False, "KT": False, "chi": True, "beta": False, "k": False, "zeta_v": True}
    q100, _, _ = readouts(levels=(1, 10, 100))
    assert identified_at(theta, (3e-4, 0.004), q100, SPACE, m=M)["Fs"]
