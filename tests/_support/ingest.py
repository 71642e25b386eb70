"""Test helpers (not jointcal code): runs of a campaign broken the way labs break them, and
what ingest says about them."""
from __future__ import annotations

import pandas as pd

from jointcal.units import G_SI  # m/s^2 per g


def _si(d: pd.DataFrame) -> None:
    d[["base_accel_g", "response_accel_g"]] *= G_SI


def _set(col, value):
    def edit(d):
        d[col] = value
    return edit


RUN, OTHER = "first_01_1g_up", "first_07_2g_up"  # a 1 g up sweep and a 2 g one, from raw_data/
FILE = f"runs/{RUN}.csv.gz"


def _scale(col: str, factor: float):
    def edit(d: pd.DataFrame) -> None:
        d[col] = d[col] * factor
    return edit
