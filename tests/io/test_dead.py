"""A response that does not follow the drive (jointcal.io._dead): a dead accelerometer flagged
and left out of the calibration, noise's share of the drive in closed form, no false positive on live runs."""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from jointcal.io import UNUSABLE_FLAGS, read_manifest, read_run
from jointcal.measure.flags import run_flags
from tests._support.campaign import REPO, example_copy
from tests.io.test_lab_channels import _ingest, write_tdms
from tests.io.test_lab_units import REAL, _as_lab_run

RUN, OTHER = "first_01_1g_up", "first_07_2g_up"


def _dead(df: pd.DataFrame) -> pd.DataFrame:
    """The response replaced by what a dead accelerometer reads: a 0.05 g offset and 0.002 g noise (seed 4)."""
    rng = np.random.default_rng(4)
    return df.assign(response_accel_g=0.05 + 0.002 * rng.standard_normal(len(df)))


@pytest.mark.parametrize("kind", ["base", "voltage"])
def test_a_dead_accelerometer_is_flagged_and_left_out(tmp_path, voltage, capsys, kind):
    """Offset and noise, nothing at the drive: flagged 'dead', made unusable for the modal stage and the
    calibration; the other run stays clean. Formerly it passed ingest silently and the modal stage said only
    low_snr and still used it."""
    campaign = example_copy(tmp_path / "example", RUN, OTHER) if kind == "base" else voltage
    ref = "base_accel_g" if kind == "base" else "drive_V"
    path, row, _ = _as_lab_run(campaign, ".tdms", lambda p, d: write_tdms(p, _dead(d), ref))
    code, lines, runs = _ingest(campaign, capsys)
    assert code == 0 and runs is not None, lines
    rid = row["run_id"]
    assert runs.loc[rid, "flags"] == "dead:response_accel_g"
    assert (runs.drop(index=rid)["flags"] == "").all()
    assert len(lines) == 1, lines
    msg = lines[0].removeprefix("jointcal: warning: ")
    assert msg.startswith(f"{path}: column 'response_accel_g' (channel 'Time Acc' of the file) does not respond to "
                          "the drive"), msg
    assert "an offset and noise" in msg and "check the accelerometer, its cable" in msg, msg
    assert f"or remove run '{rid}' from manifest.csv" in msg and msg.endswith("."), msg
    assert "dead" in UNUSABLE_FLAGS and "unusable" in run_flags(runs.loc[rid, "flags"], "low_snr", rid)[0]


def test_noise_alone_follows_the_drive_by_two_coefficients_per_window():
    """White noise against the example's drive: its share is chi^2(2 m) / N, mean 2 m / N (m windows, N samples),
    within 4 of its relative standard deviations 1 / sqrt(m); a sine at the drive's frequency: 1."""
    from jointcal.io._dead import drive_share

    row = read_manifest(REPO / "raw_data" / "manifest.csv").iloc[0]
    df = read_run(REPO / "raw_data" / row["file"], row)
    args = (row["sample_rate_hz"], row["f_start_hz"], row["f_stop_hz"], row["sweep_rate_hz_per_s"])
    drive = df["base_accel_g"].to_numpy()
    share, noise = drive_share(drive, np.random.default_rng(9).standard_normal(drive.size), *args)
    m = 480  # windows of 20 cycles in 700 -> 2500 Hz at 300 Hz/s: 6 s x 1600 Hz / 20
    assert noise == pytest.approx(2 * m / (6.0 * 12800), rel=1e-3)
    assert share == pytest.approx(noise, rel=4 / np.sqrt(m))
    assert drive_share(drive, 3.0 * drive + 0.2, *args)[0] == pytest.approx(1.0, abs=1e-9)


REAL_CHIRPS = REAL.parent / "unesp-bert-mode1"


@pytest.mark.skipif(not REAL_CHIRPS.is_dir(), reason=f"the real UNESP chirps are not at {REAL_CHIRPS} (not committed)")
def test_the_dead_check_has_no_false_positive_on_real_fast_chirps():
    """The UNESP beam's 5 Hz/s chirps ring at their mode after its passage: 15-20 % of the response follows the
    drive window by window, 80-110 times what noise alone gives (0.19 %); no run is flagged."""
    from jointcal.io import ingest_campaign

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        runs = ingest_campaign(REAL_CHIRPS, on_data_problem="flag")
    assert (runs["flags"] == "").all()


def test_the_dead_check_has_no_false_positive_on_live_runs(voltage, capsys):
    """Both voltage-driven runs, one of them as a TDMS export: live responses, no flag."""
    _as_lab_run(voltage, ".tdms", lambda p, d: write_tdms(p, d, "drive_V"))
    code, lines, runs = _ingest(voltage, capsys)
    assert code == 0 and (runs["flags"] == "").all(), lines
