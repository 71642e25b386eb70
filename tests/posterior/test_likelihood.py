"""The log-posteriors (jointcal.posterior.likelihood): the modal read-outs' is
vectorised and -inf outside the prior; residuals over their scatter sample a known Gaussian in any space."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.calibrate import PARAMS, CalibrateSettings, select_modal
from jointcal.posterior import LogPosterior
from tests._support.modal_tables import TABLE_3_2, modal_tables

CAL = CalibrateSettings()
FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])


def _lp(seed=1):
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=seed)
    return LogPosterior(select_modal(modal, "first", scatter=scatter), CAL.space, CAL.m)


def test_log_posterior_is_vectorised_and_minus_inf_outside_the_prior():
    lp = _lp()
    x_truth = np.r_[CAL.space.unit_to_x(CAL.space.to_unit(FIRST)), np.log10([3e-4, 0.012])]
    rng = np.random.default_rng(1)
    x = x_truth + 0.01 * rng.standard_normal((10, 8))
    x[3, 0] = 4.5  # Fs above its bound (1e4 lbf)
    x[4, 6] = np.log10(lp.data.rel_noise[0]) - 0.1  # sigma_f below the repeat-scatter floor
    y = lp.to_y(x)
    got = lp(y)
    assert np.isneginf(got[3]) and np.isneginf(got[4])
    assert np.all(np.isfinite(np.delete(got, [3, 4])))
    np.testing.assert_allclose(got, [lp(row[None])[0] for row in y], rtol=1e-12)
    np.testing.assert_allclose(lp.to_x(y), x, atol=1e-10)


def test_residual_posterior_samples_a_known_gaussian_in_any_space_with_a_column_held():
    """Residuals linear in two parameters of a space that is not the joint's: the posterior is Gaussian,
    a ~ N(4, 0.5^2) and b ~ N(6, 1) (n E^2 = ((a - 4)/0.5)^2 + (b - 6)^2, T = 1), and the held column stays put."""
    from jointcal.calibrate import ParamSpace
    from jointcal.posterior import ResidualPosterior, draw_quantiles, sample_ball

    space = ParamSpace((0.0, 0.0, 1.0), (10.0, 10.0, 100.0), ("a", "b", "c"), (False, False, True))

    def residuals(theta):
        a, b = space.column(theta, "a"), space.column(theta, "b")
        return np.stack([(a - 4.0) / 0.5, b - 6.0], axis=-1) / np.sqrt(2.0)

    at = space.to_unit(space.vector({"a": 5.0, "b": 5.0, "c": 10.0}))
    lp = ResidualPosterior(space, residuals, 2, 1.0, at, space.free_mask(("c",)))
    assert lp.ndim == 2
    v = np.array([[0.4, 0.6], [0.5, 0.7]])
    np.testing.assert_allclose(lp(v), [0.0, -0.5 * (1.0 / 0.25 + 1.0)], atol=1e-12)  # -(1/2) sum of squares
    assert lp(np.array([[1.2, 0.5]]))[0] == -np.inf
    ch = sample_ball(lp, np.array([0.45, 0.55]), np.array([0.01, 0.01]), walkers=32, steps=3000, seed=3)
    q = draw_quantiles(lp.physical(ch.chain[500:].reshape(-1, 2)), space.names)
    assert q.at["c", "q05"] == pytest.approx(10.0) and q.at["c", "q95"] == pytest.approx(10.0)
    for p, mu, sd in (("a", 4.0, 0.5), ("b", 6.0, 1.0)):
        assert q.at[p, "median"] == pytest.approx(mu, abs=0.1 * sd)
        assert q.at[p, "q95"] - q.at[p, "q05"] == pytest.approx(2 * 1.6449 * sd, rel=0.08)
