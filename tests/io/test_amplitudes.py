"""The reference's amplitude against the manifest's level, and the channels' roles
(jointcal.io._amplitudes): a record in m/s^2, a level typed wrong, a drive in mV, swapped channels, each flagged
in one sentence naming the file, the problem and the fix; a level within the controller's ripple passes."""
from __future__ import annotations

import warnings

import pytest

from jointcal.io import ingest_campaign
from tests._support.campaign import edit_manifest, edit_run
from tests._support.ingest import _flag, _flagged, _scale, _si


def test_record_in_si_units_is_named_and_flagged(campaign):
    edit_run(campaign, "run03.csv.gz", _si)
    flags = _flag(campaign, "run03", "run03.csv.gz", "base amplitude is 19.6 g where the manifest says level_g = 2 g",
                  "is the record in m/s^2?", "divide by 9.80665")
    assert flags == ["level:base_accel_g"]


@pytest.mark.parametrize("level, words", [
    ("10", ["base amplitude is 1 g where the manifest says level_g = 10 g", "the manifest's level",
            "correct level_g of run 'run01' in manifest.csv"]),
    ("9.80665", ["level_g = 9.80665 g", "is level_g written in m/s^2?", "write level_g of run 'run01' in g"]),
    ("2", ["level_g = 2 g", "the manifest's level"]),
])
def test_wrong_level_is_named_and_flagged(campaign, level, words):
    edit_manifest(campaign, lambda m: m.assign(level_g=m["level_g"].where(m["run_id"] != "run01", level)))
    assert _flag(campaign, "run01", "run01.csv.gz", *words) == ["level:base_accel_g"]


def test_level_within_the_controller_ripple_passes(campaign):
    edit_manifest(campaign, lambda m: m.assign(level_g=m["level_g"].where(m["run_id"] != "run01", "1.05")))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert (ingest_campaign(campaign)["flags"] == "").all()


def test_swapped_columns_are_named(campaign):
    def swap(d):
        d[["base_accel_g", "response_accel_g"]] = d[["response_accel_g", "base_accel_g"]].to_numpy()
    edit_run(campaign, "run04.csv.gz", swap)
    flags = _flag(campaign, "run04", "run04.csv.gz", "the two columns look swapped",
                  "export each channel under its own name")
    assert flags == ["swapped:base_accel_g"]


def test_a_level_v_typed_ten_times_too_large_is_flagged(voltage, capsys):
    rid = "beam_01_0.3V_up"
    edit_manifest(voltage, lambda m: m.assign(level_V=m["level_V"].where(m["run_id"] != rid, "3.0")))
    _flagged(voltage, capsys, rid, "level:drive_V", "runs/beam_01_0.3V_up.csv.gz: drive amplitude is 0.3 V where "
             "the manifest says level_V = 3 V", f"correct level_V of run '{rid}' in manifest.csv")


def test_a_drive_in_millivolts_is_named(voltage, capsys):
    rid, file = "beam_02_0.3V_down", "runs/beam_02_0.3V_down.csv.gz"
    edit_run(voltage, file, _scale("drive_V", 1000.0))
    _flagged(voltage, capsys, rid, "level:drive_V", file, "is drive_V in mV?", "export drive_V in V (divide by 1000)")


def test_swapped_drive_and_response_on_a_voltage_run_are_named(voltage, capsys):
    rid, file = "beam_01_0.3V_up", "runs/beam_01_0.3V_up.csv.gz"
    edit_run(voltage, file, lambda d: d.rename(columns={"drive_V": "response_accel_g", "response_accel_g": "drive_V"}))
    runs = _flagged(voltage, capsys, rid, "swapped:drive_V", file, "the drive voltage is flat",
                    "the two columns look swapped", "export each channel under its own name")
    assert runs.loc[rid, "f_first_hz"] == pytest.approx(60.0, abs=2.0)  # the band is read from the true drive
