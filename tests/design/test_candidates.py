"""The tests a user can run next (jointcal.design.candidates): the round level series,
levels, rates and directions with their duration."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.design import DesignSettings, candidates, level_series


def _runs(levels=(1.0, 1.0, 2.0, 5.0, 10.0), rate=300.0):
    return pd.DataFrame({"assembly": "first", "level_g": levels, "direction": ["up", "down"] * (len(levels) // 2)
                         + ["up"] * (len(levels) % 2), "f_start_hz": 700.0, "f_stop_hz": 2500.0,
                         "sweep_rate_hz_per_s": rate})


def test_level_series_is_the_round_series_between_the_campaign_and_the_limit():
    assert level_series(1.0, 100.0) == [1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 50, 70, 100]
    assert level_series(0.8, 45.0) == [0.8, 1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 45]


def test_candidates_cover_levels_rates_and_directions_with_their_duration():
    c = candidates(_runs(), DesignSettings(max_level_g=20.0, rate_factors=(0.5, 2.0)))
    assert len(c) == 9 * 2 * 2  # 1, 1.5, 2, 3, 5, 7, 10, 15, 20 g, two rates, two directions
    assert set(c["sweep_rate_hz_per_s"]) == {150.0, 600.0}
    np.testing.assert_allclose(c["duration_s"], 1800.0 / c["sweep_rate_hz_per_s"])
    assert not c["repeat"].any()  # the campaign ran at 300 Hz/s, no candidate rate
    c = candidates(_runs(), DesignSettings(max_level_g=20.0, rate_factors=(1.0,)))
    assert set(c.loc[c["repeat"], "level_g"]) == {1.0, 2.0, 5.0, 10.0}
    assert not c[(c["level_g"] == 10.0) & (c["direction"] == "down")]["repeat"].any()  # 10 g was run up only
    with pytest.raises(ValueError, match="design.levels must lie in"):
        DesignSettings(levels=(200.0,))
