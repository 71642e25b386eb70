"""The time axis (jointcal.io._time): a time unit guessed and named, jitter named, times rounded
when written not mistaken for jitter."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io._time import check_time, time_resolution
from tests._support.campaign import edit_run
from tests._support.ingest import FILE, _raises, _stopped


@pytest.mark.parametrize("scale, unit, fix", [(1e3, "milliseconds", "multiply by 0.001"),
                                              (1e6, "microseconds", "multiply by 1e-06"),
                                              (12800.0, "sample numbers", "multiply by 7.8125e-05")])
def test_time_unit_is_guessed_and_named(campaign, scale, unit, fix):
    def rescale(d):
        d["time_s"] = d["time_s"] * scale
    edit_run(campaign, "run01.csv.gz", rescale)
    _raises(campaign, "run01.csv.gz", f"means it is written in {unit}", f"export time_s in seconds ({fix})")


def test_jittered_time_is_named(example, capsys):
    rng = np.random.default_rng(5)

    def jitter(d: pd.DataFrame) -> None:
        d["time_s"] = d["time_s"] + rng.uniform(-0.1, 0.1, len(d)) / 12800.0  # +/- 10 % of a step per sample
    edit_run(example, FILE, jitter)
    _stopped(example, capsys, FILE, "time_s is not evenly spaced", "of a step off a uniform grid",
             "export the DAQ's own sample times (t0 + i / sample rate)")


@pytest.mark.parametrize("fmt, bound", [("%.7g", 5e-6), ("%.5f", 5e-6), ("float32", 2.0**-24 * 60)])
def test_rounded_times_are_not_jitter(fmt, bound):
    """A 60 s record at 12.8 kHz written with 7 significant digits or 5 decimals (rounded by up to 6 % of a
    step), or in float32 (3 %): the way the times were written, not jitter."""
    t = np.arange(int(60 * 12800)) / 12800.0
    t = t.astype(np.float32).astype(float) if fmt == "float32" else np.array([float(fmt % v) for v in t])
    assert time_resolution(t).max() == pytest.approx(bound, rel=0.01)
    assert check_time(t, 12800.0, "r.csv", "'r'") == pytest.approx(12800.0, rel=1e-6)
