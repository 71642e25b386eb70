"""One record against its manifest row (jointcal.io._checks, validate_run): a free-decay tail
accepted, a dead or all-NaN channel named."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io import read_manifest, read_run, validate_run
from tests._support.campaign import edit_run
from tests._support.ingest import _flag, _set


def test_free_decay_tail_is_accepted(small_campaign):
    row = read_manifest(small_campaign / "manifest.csv").iloc[1]  # a down sweep
    df = read_run(small_campaign / row["file"])
    n_tail = 4000  # 0.31 s more of silence after the sweep
    tail = pd.DataFrame({"time_s": df["time_s"].iloc[-1] + np.arange(1, n_tail + 1) / 12800.0,
                         "base_accel_g": 0.0, "response_accel_g": 0.0})
    checks = validate_run(pd.concat([df, tail], ignore_index=True), row, "long.csv")
    assert checks["n_samples"] == len(df) + n_tail
    assert abs(checks["f_last_hz"] - 1500.0) < 5.0


@pytest.mark.parametrize("col", ["response_accel_g", "base_accel_g"])
def test_zero_channel_is_named(campaign, col):
    edit_run(campaign, "run02.csv.gz", _set(col, 0.0))
    flags = _flag(campaign, "run02", "run02.csv.gz", f"'{col}' is constant at 0 (no signal recorded)",
                  "check the sensor, its cable")
    assert flags == [f"constant:{col}"]


def test_all_nan_base_is_reported_as_nan_not_as_a_wrong_sweep(campaign):
    edit_run(campaign, "run02.csv.gz", _set("base_accel_g", np.nan))
    flags = _flag(campaign, "run02", "run02.csv.gz", "'base_accel_g' has 9600 NaN/inf values")
    assert flags == ["nonfinite:base_accel_g"]
