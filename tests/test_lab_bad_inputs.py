"""Bad lab exports that passed in silence or a traceback, each on a file written here with pyuff, npTDMS or
scipy.io directly (not the project's writer), read by `jointcal ingest --on-data-problem flag` (the workflow's
policy): a zero or missing sample interval, a file cut short, a dead accelerometer. Each stops with one sentence
naming the file and the fix, or flags its run (and the flagged run is left out of the calibration)."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import pyuff
import scipy.io
from tests._support.campaign import REPO, example_copy
from nptdms import ChannelObject, GroupObject, TdmsWriter
from tests.test_lab_units import DIMS, REAL, _as_lab_run, _quantity, write_testlab_mks, write_uff_units

from jointcal.cli import main
from jointcal.io import CampaignWarning, UNUSABLE_FLAGS, read_manifest, read_run
from jointcal.measure.flags import run_flags
from jointcal.units import G_SI

RUN, OTHER = "first_01_1g_up", "first_07_2g_up"


def _ingest(campaign: Path, capsys) -> tuple[int, list[str], pd.DataFrame | None]:
    """Exit status, stderr lines and runs.csv (None when not written) of `jointcal ingest --on-data-problem flag`."""
    out = campaign.parent / "results" / "runs.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CampaignWarning)
        code = main(["ingest", str(campaign), str(out), "--on-data-problem", "flag"])
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return code, err.strip().splitlines(), (pd.read_csv(out, keep_default_na=False).set_index("run_id")
                                            if out.exists() else None)


def _stopped(campaign: Path, capsys, *words: str) -> str:
    code, lines, runs = _ingest(campaign, capsys)
    assert code == 2 and runs is None and len(lines) == 1 and lines[0].startswith("jointcal: "), lines
    msg = lines[0]
    assert all(w in msg for w in words) and msg.endswith("."), msg
    return msg


def write_tdms(path: Path, df: pd.DataFrame, ref: str, *, dt: float | None = None, units: bool = True,
               cut: float | None = None) -> None:
    """The reference and response of `df` as waveforms 'Run/Time Drive' and 'Run/Time Acc' (npTDMS), with
    wf_increment `dt` (the record's own by default; None: left out when `dt` is NaN), cut to `cut` of its bytes."""
    step = (df["time_s"].iloc[-1] - df["time_s"].iloc[0]) / (len(df) - 1) if dt is None else dt
    props = {} if step != step else {"wf_increment": step, "wf_start_offset": 0.0}
    unit = {"base_accel_g": "g", "drive_V": "V"}
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([GroupObject("Run"),
                              ChannelObject("Run", "Time Drive", df[ref].to_numpy(),
                                            properties={**props, **({"unit_string": unit[ref]} if units else {})}),
                              ChannelObject("Run", "Time Acc", df["response_accel_g"].to_numpy(),
                                            properties={**props, **({"unit_string": "g"} if units else {})})])
    if cut is not None:
        raw = path.read_bytes()
        path.write_bytes(raw[:int(cut * len(raw))])


# ------------------------------------------------------------------------ the sample interval


@pytest.mark.parametrize("fmt, field", [("tdms", "wf_increment"), ("uff", "abscissa_inc"),
                                        ("mat", "x_values.increment")])
def test_a_zero_sample_interval_is_one_sentence(voltage, capsys, fmt, field):
    """Formerly a raw ZeroDivisionError in the reader."""
    def write(path, df):
        if fmt == "tdms":
            write_tdms(path, df, "drive_V", dt=0.0)
        elif fmt == "uff":
            write_uff_units(path, df.assign(time_s=0.0 * df["time_s"]), 1)
        else:
            write_testlab_mks(path, 0.0 * df["time_s"].to_numpy(), {
                "Drive": (df["drive_V"].to_numpy(), _quantity("V", 1.0, DIMS["voltage"])),
                "Acc": (df["response_accel_g"].to_numpy() * G_SI, _quantity("g", 1 / G_SI, DIMS["acceleration"]))})
    path, _, _ = _as_lab_run(voltage, f".{fmt}", write)
    _stopped(voltage, capsys, f"{path}: channel", f"has a sample interval of 0", f"({field})",
             "export the record with its sample interval (1 / the sample rate)")


@pytest.mark.parametrize("fmt", ["tdms", "mat"])
def test_a_missing_sample_interval_is_one_sentence(voltage, capsys, fmt):
    def write(path, df):
        if fmt == "tdms":
            write_tdms(path, df, "drive_V", dt=float("nan"))
        else:
            scipy.io.savemat(path, {"Time_Acc": {"x_values": {"start_value": 0.0, "number_of_values": len(df)},
                                                 "y_values": {"values": df["response_accel_g"].to_numpy()},
                                                 "function_record": {"name": "Time Acc"}}})
    path, _, _ = _as_lab_run(voltage, f".{fmt}", write)
    words = ["has no wf_increment (the sample interval)", "save the channels as waveforms"] if fmt == "tdms" else \
        ["lacks x_values.start_value / x_values.increment", "export the time signals from Test.Lab with their x_values"]
    _stopped(voltage, capsys, str(path), *words)


# ------------------------------------------------------------------------ a file cut short


@pytest.mark.parametrize("fmt, binary", [("uff", 1), ("uff", 0), ("tdms", None), ("mat", None)])
def test_a_file_cut_short_is_said_as_such(voltage, capsys, fmt, binary):
    """Cut at 90 % of its bytes: formerly "no channel 'Time Acc'" (UFF: pyuff drops the cut data set) or
    "different time axes ... 9600 and 7676 samples" (TDMS), blaming the channels."""
    def write(path, df):
        if fmt == "tdms":
            write_tdms(path, df, "drive_V", cut=0.9)
            return
        if fmt == "uff":
            write_uff_units(path, df, 1)
            if binary == 0:  # the same sets as ASCII
                sets = pyuff.UFF(str(path)).read_sets()
                path.unlink()
                pyuff.UFF(str(path)).write_sets([{**s, "binary": 0} if s["type"] == 58 else s for s in sets], "add")
        else:
            write_testlab_mks(path, df["time_s"].to_numpy(), {
                "Drive": (df["drive_V"].to_numpy(), _quantity("V", 1.0, DIMS["voltage"])),
                "Acc": (df["response_accel_g"].to_numpy() * G_SI, _quantity("g", 1 / G_SI, DIMS["acceleration"]))})
        raw = path.read_bytes()
        path.write_bytes(raw[:int(0.9 * len(raw))])
    path, _, _ = _as_lab_run(voltage, f".{fmt}", write)
    msg = _stopped(voltage, capsys, str(path), "cut short", "export the run again (or copy the whole file")
    assert "could not read bytes" in msg or fmt != "mat"
    assert "no channel" not in msg and "different time axes" not in msg


def test_a_testlab_signal_with_fewer_values_than_it_announces_is_cut_short(voltage, capsys):
    def write(path, df):
        t = df["time_s"].to_numpy()
        write_testlab_mks(path, t, {
            "Drive": (df["drive_V"].to_numpy(), _quantity("V", 1.0, DIMS["voltage"])),
            "Acc": (df["response_accel_g"].to_numpy() * G_SI, _quantity("g", 1 / G_SI, DIMS["acceleration"]))})
        mat = scipy.io.loadmat(path, simplify_cells=True)
        mat["Time_Acc"]["y_values"]["values"] = mat["Time_Acc"]["y_values"]["values"][: t.size * 4 // 5]
        scipy.io.savemat(path, {k: v for k, v in mat.items() if not k.startswith("__")})
    path, _, _ = _as_lab_run(voltage, ".mat", write)
    _stopped(voltage, capsys, str(path), "struct 'Time_Acc' holds", "of its", "values (x_values.number_of_values): "
             "the file is cut short")


# ------------------------------------------------------------------------ a dead accelerometer


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
