"""Candidate tests: what the user can run next on the same rig, and what each costs in shaker time.

A candidate is one swept-sine run over the campaign's band: a base level (g), a sweep
direction and a sweep rate. Levels: the series 1, 1.5, 2, 3, 5, 7 x 10^n from the
campaign's lowest level up to the configured shaker limit (and the limit itself), or the
configured list, together with the levels already run; rates: the campaign's rate times
each configured factor (slower and faster sweeps); both directions. Cost: the sweep's
duration over the band, seconds.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .settings import DesignSettings

__all__ = ["ROUND_SERIES", "level_series", "campaign_sweep", "candidates"]

ROUND_SERIES = (1.0, 1.5, 2.0, 3.0, 5.0, 7.0)  # levels per decade an engineer dials in


def level_series(lowest: float, limit: float) -> list[float]:
    """The round series between `lowest` and `limit` (g), both ends included."""
    out = []
    for n in range(int(np.floor(np.log10(lowest))) - 1, int(np.ceil(np.log10(limit))) + 1):
        out += [v * 10.0**n for v in ROUND_SERIES]
    vals = [round(v, 10) for v in out if lowest * (1 - 1e-9) <= v <= limit * (1 + 1e-9)]
    return sorted(set(vals) | {float(lowest), float(limit)})


def campaign_sweep(runs: pd.DataFrame) -> dict[str, float]:
    """The campaign's band (Hz) and its most common sweep rate (Hz/s) from its runs table.

    Parameters
    ----------
    runs : DataFrame
        One assembly's rows of the ingest stage's ``runs.csv`` (or the manifest): f_start_hz,
        f_stop_hz, sweep_rate_hz_per_s.
    """
    lo = float(np.nanmin(np.minimum(runs["f_start_hz"], runs["f_stop_hz"])))
    hi = float(np.nanmax(np.maximum(runs["f_start_hz"], runs["f_stop_hz"])))
    rate = float(pd.to_numeric(runs["sweep_rate_hz_per_s"], errors="coerce").mode().iloc[0])
    return {"f_lo_hz": lo, "f_hi_hz": hi, "rate_hz_per_s": rate}


def candidates(runs: pd.DataFrame, settings: DesignSettings) -> pd.DataFrame:
    """Every candidate test of one assembly.

    Parameters
    ----------
    runs : DataFrame
        The assembly's runs (level_g, direction, f_start_hz, f_stop_hz, sweep_rate_hz_per_s).
    settings : DesignSettings

    Returns
    -------
    pandas.DataFrame
        One row per candidate: level_g, direction, sweep_rate_hz_per_s, f_lo_hz, f_hi_hz,
        duration_s, repeat (the campaign already holds a run at this level, direction and
        rate), ordered by level, rate and direction.
    """
    sweep = campaign_sweep(runs)
    measured = sorted(float(v) for v in pd.to_numeric(runs["level_g"], errors="coerce").dropna().unique())
    levels = (sorted(set(map(float, settings.levels))) if settings.levels
              else level_series(min(measured), settings.max_level_g))
    levels = sorted(set(levels) | {v for v in measured if v <= settings.max_level_g})
    done = {(float(r.level_g), str(r.direction), float(r.sweep_rate_hz_per_s)) for r in runs.itertuples()}
    rows = []
    for level in levels:
        for factor in sorted(settings.rate_factors):
            rate = sweep["rate_hz_per_s"] * float(factor)
            for d in settings.directions:
                rows.append(dict(level_g=level, direction=d, sweep_rate_hz_per_s=rate, f_lo_hz=sweep["f_lo_hz"],
                                 f_hi_hz=sweep["f_hi_hz"], duration_s=(sweep["f_hi_hz"] - sweep["f_lo_hz"]) / rate,
                                 repeat=any(abs(level - a) < 1e-9 and d == b and abs(rate - c) < 1e-6 * rate
                                            for a, b, c in done)))
    return pd.DataFrame(rows)
