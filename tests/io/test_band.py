"""The drive's band (jointcal.io._band): a silent pre-trigger head named, and read from the
manifest's sweep_start_s."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io import read_manifest, read_run
from tests._support.campaign import REPO, edit_manifest, edit_run
from tests._support.ingest import FILE, OTHER, RUN, _ingest, _stopped


def _with_head(seconds: float):
    def edit(d: pd.DataFrame) -> pd.DataFrame:
        n = int(round(seconds * 12800))
        rng = np.random.default_rng(2)
        head = pd.DataFrame({c: 1e-4 * rng.standard_normal(n) for c in ("base_accel_g", "response_accel_g")})
        out = pd.concat([head, d[["base_accel_g", "response_accel_g"]]], ignore_index=True)
        return out.assign(time_s=np.arange(len(out)) / 12800.0)[["time_s", "base_accel_g", "response_accel_g"]]
    return edit


def test_a_silent_pre_trigger_head_is_named_and_sweep_start_s_reads_the_run(example, capsys):
    edit_run(example, FILE, _with_head(0.25))
    _stopped(example, capsys, FILE, "the drive starts 0.25 s after the record's first sample (a silent pre-trigger "
             "head of 3200 samples)", "trim the head", f"sweep_start_s column (0.25 for run '{RUN}')")
    edit_manifest(example, lambda m: m.assign(sweep_start_s=np.where(m["run_id"] == RUN, "0.25", "")))
    code, err, runs = _ingest(example, capsys)
    assert code == 0 and (runs["flags"] == "").all(), err
    assert runs.loc[RUN, "f_first_hz"] == pytest.approx(700.0, abs=5.0)
    assert runs.loc[RUN, "sweep_start_s"] == 0.25 and runs.loc[OTHER, "sweep_start_s"] == 0.0
    row = read_manifest(example / "manifest.csv").iloc[0]
    assert len(read_run(example / FILE, row)) == len(read_run(REPO / "raw_data" / FILE))
