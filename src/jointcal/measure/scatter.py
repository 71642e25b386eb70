"""Scatter of the read-outs across repeats and up/down pairs: the measurement's own noise."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..io.contract import UNUSABLE, level_column
from .testkinds import methods

__all__ = ["scatter"]


def scatter(table: pd.DataFrame) -> pd.DataFrame:
    """Scatter of f_res and damping across repeats and up/down pairs, per assembly (and mode, where the
    table has a ``mode`` column: one row per run and mode, `jointcal.measure.campaign`).

    Rows (assembly[, mode], quantity, level, source): 'repeats' for a level run more than twice,
    'up_down' for a level with one up/down pair, and one 'pooled' row per (assembly,
    quantity) with the dof-weighted pooled relative standard deviation (level NaN).
    Rows flagged unusable are left out, and so are dwell and ring-down rows (``f_res_method``
    ``dwell`` or ``ringdown``): a level's dwells are at different frequencies and amplitudes, and a
    ring-down's row is its own largest window, none a repeat of another.
    """
    level = level_column(table.columns) or "level_g"
    ok = ~table["flags"].fillna("").str.contains(UNUSABLE)
    if "f_res_method" in table.columns:
        ok &= ~table["f_res_method"].isin(methods())  # the test kinds' read-outs (`jointcal.measure.testkinds`)
    keys = ["assembly", "mode"] if "mode" in table.columns else ["assembly"]
    rows = []
    for key, grp in table[ok].groupby(keys, sort=False):
        unit = dict(zip(keys, key))
        for qty in ("f_res_hz", "zeta_res", "zeta_phase_resonance", "zeta_half_power"):
            if qty not in grp.columns:
                continue
            ss, dof = 0.0, 0
            for lev, g in grp.groupby(level, sort=True):
                v = g[qty].dropna().to_numpy(float)
                if v.size < 2:
                    continue
                sd = float(np.std(v, ddof=1))
                rel = sd / abs(v.mean())
                rows.append(dict(**unit, quantity=qty, level=lev, source="repeats" if v.size > 2 else "up_down",
                                 n=v.size, mean=float(v.mean()), std=sd, rel_std=rel))
                ss += rel**2 * (v.size - 1)
                dof += v.size - 1
            rows.append(dict(**unit, quantity=qty, level=np.nan, source="pooled", n=dof,
                             mean=np.nan, std=np.nan, rel_std=float(np.sqrt(ss / dof)) if dof else np.nan))
    out = pd.DataFrame(rows, columns=[*keys, "quantity", "level", "source", "n", "mean", "std", "rel_std"])
    return out.rename(columns={"level": level})
