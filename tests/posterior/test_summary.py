"""The chain's summary (jointcal.posterior.summary): unconstrained parameters and
correlations said."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.posterior import constraints_text, summarize


def test_summary_flags_unconstrained_parameters_and_correlations():
    rng = np.random.default_rng(2)
    lower = np.array([0.0, 4.0, -0.95, -4.0, 4.0, -4.0, -4.0, -2.0])
    upper = np.array([4.0, 8.0, 0.0, 0.7, 8.0, -1.0, -1.3, -0.3])
    chain = np.empty((2000, 16, 8))
    chain[...] = (lower + upper) / 2 + 0.01 * rng.standard_normal(chain.shape)
    chain[..., 3] = rng.uniform(lower[3], upper[3], chain.shape[:2])  # beta: flat over its prior
    chain[..., 4] = chain[..., 1] + 0.001 * rng.standard_normal(chain.shape[:2])  # k follows KT
    s = summarize(chain, lower, upper, burn=100)
    assert list(s.columns) == ["param", "unit", "median", "q05", "q95", "tau", "n_eff", "prior_lo", "prior_hi",
                               "width_ratio", "constrained"]
    row = s.set_index("param")
    assert row.loc["beta", "width_ratio"] == pytest.approx(0.9, abs=0.02) and not row.loc["beta", "constrained"]
    assert row.loc["chi", "constrained"] and row.loc["KT", "median"] == pytest.approx(1e6, rel=0.01)
    text = constraints_text(s, chain, burn=100, q_max=1e-3)
    assert "beta is not constrained by the data" in text
    assert "as KT rises, k rises" in text
