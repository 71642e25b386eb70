"""The ranking rule (jointcal.design.recommend): the lowest level that identifies, then the
shortest sweep within the sampling error."""
from __future__ import annotations

import pandas as pd

from jointcal.design import rank


def _table(rows):
    t = pd.DataFrame(rows, columns=["level_g", "direction", "sweep_rate_hz_per_s", "share_targets", "ratio_Fs"])
    t["duration_s"] = 1800.0 / t["sweep_rate_hz_per_s"]
    t["eig_nats"] = 1.0
    return t


def test_rank_takes_the_lowest_level_that_identifies_then_the_shortest_sweep_within_the_sampling_error():
    t = _table([(10, "up", 300, 0.05, 1.1), (50, "up", 300, 0.96, 8.0), (50, "up", 1200, 0.95, 7.5),
                (50, "down", 1200, 0.95, 7.5), (100, "up", 300, 0.99, 9.0), (50, "up", 2400, 0.90, 6.0)])
    r = rank(t, ["Fs"], 0.9, ["up", "down"], n_draws=200)
    # 0.95 lies within one binomial standard error (0.014 at 0.96 and 200 draws) of the level's best, 0.90 does not
    assert r.loc[0, ["level_g", "direction", "sweep_rate_hz_per_s"]].tolist() == [50, "up", 1200]
    assert r.loc[0, "identifies"] and r["rank"].tolist() == list(range(1, 7))
    assert r.iloc[-1]["level_g"] == 10  # the level that identifies at the smallest share ranks last
    none = rank(t.assign(share_targets=t["share_targets"] * 0.5), ["Fs"], 0.9, ["up", "down"], n_draws=200)
    assert none.loc[0, "level_g"] == 100 and not none["identifies"].any()  # none reaches 90%: the largest share
