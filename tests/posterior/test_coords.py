"""The sampler's coordinates (jointcal.posterior.coords): a round trip, with the stated
Jacobian."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.posterior import log_det_dy_dx, x_to_y, y_to_x


def test_sampler_coordinates_round_trip_with_the_stated_jacobian():
    rng = np.random.default_rng(0)
    x = np.column_stack([rng.uniform(0, 4, 20), rng.uniform(4, 8, 20), rng.uniform(-0.95, 0, 20),
                         rng.uniform(-4, 0.7, 20), rng.uniform(4, 8, 20), rng.uniform(-4, -1, 20)])
    y = x_to_y(x, 1e-4)
    np.testing.assert_allclose(y_to_x(y, 1e-4), x, atol=1e-10)
    h = 1e-6
    for xi in x[:5]:
        J = np.array([(x_to_y(xi + h * e, 1e-4) - x_to_y(xi - h * e, 1e-4)) / (2 * h) for e in np.eye(6)]).T
        assert np.log(abs(np.linalg.det(J))) == pytest.approx(log_det_dy_dx(x_to_y(xi, 1e-4)), abs=1e-6)
