"""Test helpers (not jointcal code): samples with a known answer."""
from __future__ import annotations

import numpy as np


def _bimodal(n=12000, weight=0.3, sep=6.0, seed=1):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((n, 8))
    second = rng.random(n) < weight
    x[second, 0] += sep  # separated along one coordinate ...
    x[:, 3] = rng.uniform(0, 1, n)  # ... with a flat (unconstrained) coordinate alongside
    return x, second
