"""The manifest's test kinds (jointcal.io._kinds): sweep by default, dwell and ringdown, and their checks."""
from __future__ import annotations

import pandas as pd
import pytest
from _campaign import EXAMPLE, example_copy, edit_manifest
from _kinds_records import dwell_row, kinds_campaign, linear_dwell

from jointcal.io import CampaignError, ingest_campaign, read_manifest


def _one_sentence(msg: str, *words: str) -> None:
    assert all(w in msg for w in words), msg
    assert "\n" not in msg and msg.endswith("."), msg


@pytest.fixture(scope="module")
def records():
    return {f"d{int(f)}": linear_dwell(512.0, f, 0.5, 8.0, 4.0) for f in (18.0, 20.0)}


def _campaign(tmp_path, records, edit=None):
    rows = [dwell_row("d18", 18.0, 1), dwell_row("d20", 20.0, 2), dwell_row("r20", 0, 3, test="ringdown")]
    recs = {**records, "r20": records["d20"]}
    if edit:
        edit(rows)
    return kinds_campaign(tmp_path / "c", rows, recs)


def test_dwell_and_ringdown_runs_ingest_with_empty_sweep_columns(tmp_path, records):
    runs = ingest_campaign(_campaign(tmp_path, records)).set_index("run_id")
    assert list(runs["test"]) == ["dwell", "dwell", "ringdown"]
    assert runs[["f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s"]].isna().all().all()
    assert (runs["flags"] == "").all()
    assert abs(runs.loc["d18", "f_first_hz"] - 18.0) < 0.01  # the drive's frequency over the dwell


def test_a_campaign_without_sweeps_may_leave_the_sweep_columns_out(tmp_path, records):
    def drop(rows):
        for r in rows:
            for c in ("direction", "f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s"):
                del r[c]
    runs = ingest_campaign(_campaign(tmp_path, records, drop))
    assert len(runs) == 3 and runs["f_start_hz"].isna().all()


@pytest.mark.parametrize("edit, words", [
    (lambda rows: rows[0].update(test="stepped"), ["line 2", "test 'stepped' is not a test kind",
                                                   "sweep, dwell, ringdown"]),
    (lambda rows: rows[0].update(dwell_hz=""), ["line 2", "dwell_hz is empty (a dwell run needs it)",
                                                "fill in dwell_hz"]),
    (lambda rows: rows[0].update(dwell_hz="-3"), ["dwell_hz '-3' is not a positive number"]),
    (lambda rows: rows[0].update(dwell_hz="300"), ["dwell_hz 300 Hz is above Nyquist (256 Hz)"]),
    (lambda rows: rows[1].update(dwell_hz="21"), ["d20.csv", "the drive's frequency over the dwell is 20 Hz, not "
                                                  "dwell_hz = 21 Hz", "correct dwell_hz of run 'd20'"]),
    (lambda rows: rows[2].update(test="sweep"), ["line 4", "direction is empty", "fill in direction"]),
    (lambda rows: rows[0].update(level_V="0.05"), ["d18.csv", "drive amplitude is 0.5 V where the manifest says "
                                                   "level_V = 0.05 V"]),
])
def test_kind_mistakes_are_one_sentence(tmp_path, records, edit, words):
    with pytest.raises(CampaignError) as info:
        ingest_campaign(_campaign(tmp_path, records, edit))
    _one_sentence(str(info.value), *words)


def test_dwell_column_is_needed_when_a_run_is_a_dwell(tmp_path, records):
    def drop(rows):
        for r in rows:
            del r["dwell_hz"]
    with pytest.raises(CampaignError) as info:
        read_manifest(_campaign(tmp_path, records, drop) / "manifest.csv")
    _one_sentence(str(info.value), "column(s) dwell_hz missing", "use the header")


def test_a_short_dwell_is_named(tmp_path):
    rec = {"d18": linear_dwell(512.0, 18.0, 0.5, 1.0, 4.0), "d20": linear_dwell(512.0, 20.0, 0.5, 8.0, 1.0)}
    with pytest.raises(CampaignError) as info:
        ingest_campaign(_campaign(tmp_path, rec))
    _one_sentence(str(info.value), "the drive of dwell run 'd18' lasts 1 s, fewer than 40 cycles")


@pytest.mark.parametrize("test", [None, "", "sweep", "Sweep"])
def test_sweeps_are_the_default_and_read_as_before(tmp_path, test):
    ids = ("first_01_1g_up", "first_02_1g_down")
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    before = ingest_campaign(example_copy(tmp_path / "a", *ids))
    campaign = example_copy(tmp_path / "b", *ids)
    if test is not None:
        edit_manifest(campaign, lambda df: df.insert(2, "test", test))  # not last: an empty last cell is a comma
    after = ingest_campaign(campaign)
    assert ("test" in after) == (test is not None)
    pd.testing.assert_frame_equal(before, after.drop(columns=["test"], errors="ignore"))
    assert test is None or set(after["test"]) == {"sweep"}
    assert EXAMPLE.is_dir()
