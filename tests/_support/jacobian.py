"""Test helper (not jointcal code): a sweep-fit Jacobian held against the central difference of its own misfit."""
from __future__ import annotations

import numpy as np


def assert_matches_central_difference(prob, pf: np.ndarray, free: np.ndarray) -> None:
    """Each column of ``prob.jacobian_matrix(pf, free)`` within 1e-6 (relative) of the Richardson-extrapolated
    central difference of ``prob.misfit`` (steps 5e-6 and 1e-5: error O(e^4))."""
    jac = prob.jacobian_matrix(pf, free)
    for j in range(free.size):
        def central(e):
            up, down = pf.copy(), pf.copy()
            up[j] += e
            down[j] -= e
            return (prob.misfit(up, free) - prob.misfit(down, free)) / (2 * e)
        fd = (4 * central(5e-6) - central(1e-5)) / 3
        assert np.linalg.norm(jac[:, j] - fd) <= 1e-6 * np.linalg.norm(fd) + 1e-9, f"p[{free[j]}]"
