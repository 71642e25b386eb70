"""Each lab format's channels (jointcal.io._lab_channels), on files written here with pyuff,
npTDMS or scipy.io directly (not the project's writer), read by `jointcal ingest --on-data-problem flag` (the
workflow's policy): a zero or missing sample interval and a file cut short, formerly passed in silence or a
traceback, each one sentence naming the file and the fix."""
from __future__ import annotations

import warnings
from pathlib import Path

import pandas as pd
import pytest
import pyuff
import scipy.io
from nptdms import ChannelObject, GroupObject, TdmsWriter

from jointcal.cli import main
from jointcal.io import CampaignWarning
from jointcal.units import G_SI
from tests.io.test_lab_units import DIMS, _as_lab_run, _quantity, write_testlab_mks, write_uff_units


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
