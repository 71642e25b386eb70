"""The manifest's test kinds (jointcal.io.testkinds): sweep by default, dwell and ringdown, and their checks."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io import CampaignError, ingest_campaign, read_manifest, read_run
from tests._support.campaign import EXAMPLE, example_copy, edit_manifest
from tests._support.kinds_records import dwell_row, kinds_campaign, linear_dwell


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


def _testlab_pair(folder, rid, rec):
    """A run exported as Test.Lab does it: the response in <rid>_Time.mat, the drive apart in <rid>_TimeShaker.mat."""
    from tests.io.test_lab_formats import write_testlab

    folder.mkdir(parents=True, exist_ok=True)
    write_testlab(folder / f"{rid}_Time.mat", rec[["time_s", "response_accel_g"]], {"response_accel_g": "g"})
    write_testlab(folder / f"{rid}_TimeShaker.mat", rec[["time_s", "drive_V"]], {"drive_V": "V"})


def test_a_drive_exported_apart_is_read_from_reference_file(tmp_path, records):
    from tests.io.test_lab_formats import NAMES

    lab = tmp_path / "lab"
    for rid, rec in (("d18", "d18"), ("d20", "d20"), ("r20", "d20")):
        _testlab_pair(lab, rid, records[rec])
    rows = [dwell_row("d18", 18.0, 1), dwell_row("d20", 20.0, 2), dwell_row("r20", 0, 3, test="ringdown")]
    for r, rid, ref in zip(rows, ("d18", "d20", "r20"), (True, True, False)):  # r20: its drive not recorded
        r.update(file=f"../lab/{rid}_Time.mat", response_channel=NAMES["response_accel_g"],
                 reference_channel=NAMES["drive_V"] if ref else "",
                 reference_file=f"../lab/{rid}_TimeShaker.mat" if ref else "", note="lab export")
    campaign = kinds_campaign(tmp_path / "c", rows, {})
    runs = ingest_campaign(campaign).set_index("run_id")
    plain = ingest_campaign(_campaign(tmp_path, records)).set_index("run_id")
    for col in ("f_first_hz", "rms_drive_V", "rms_response_accel_g"):  # the dwells as from one CSV file each
        assert np.allclose(runs[col][:2].to_numpy(float), plain[col][:2].to_numpy(float), rtol=1e-6), col
    assert runs.loc["r20", "rms_drive_V"] == 0 and np.isclose(runs.loc["r20", "rms_response_accel_g"],
                                                              plain.loc["r20", "rms_response_accel_g"], rtol=1e-6)
    assert (runs["flags"] == "").all()
    rec = read_run(campaign / rows[2]["file"], runs.loc["r20"].to_dict() | {"run_id": "r20"})
    assert (rec["drive_V"] == 0).all() and rec.attrs["sources"]["drive_V"]["name"] == "not recorded"
    rows[0]["reference_file"] = "../lab/d19_TimeShaker.mat"
    with pytest.raises(CampaignError) as info:
        ingest_campaign(kinds_campaign(tmp_path / "c", rows, {}))
    _one_sentence(str(info.value), "d19_TimeShaker.mat",
                  "the reference_file of run 'd18' listed in manifest.csv (line 2) does not exist")
