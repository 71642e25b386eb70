"""Units as each lab format stores them (jointcal.io._lab_units), on files the project's writer did not make:
Test.Lab MATLAB exports saved in MKS (the lab's own five dwells, opt-in, and structs written here with scipy.io
the way Test.Lab writes them), UFF 58 whose unit is said by its exponents and data set 164 (pyuff, each unit
code), and labels that disagree with the stored quantity. The real files are read from ../shared/real/ (or the
folder JOINTCAL_REAL_DATA names); the tests that need them skip, with the reason, when they are absent."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import pyuff
import scipy.io

from jointcal.io import CampaignError, ingest_campaign, read_manifest, read_run
from jointcal.io._lab_channels import lab_channels
from jointcal.units import G_SI, INCH_M, LBF_N  # m/s^2 per g, m per inch, N per lbf
from tests._support.campaign import REPO, edit_manifest
from tests._support.ingest import _one_sentence

REAL = Path(os.environ.get("JOINTCAL_REAL_DATA", REPO.parent / "shared" / "real")) / "unesp-bert-dwell-mode1"
TERMS = ("LENGTH", "ANGLE", "MASS", "TIME", "CURRENT", "LIGHT", "TEMPERATURE", "MOLCULAR_AMOUNT")
DIMS = {"acceleration": {"LENGTH": 1, "TIME": -2}, "voltage": {"LENGTH": 2, "MASS": 1, "TIME": -3, "CURRENT": -1},
        "time": {"TIME": 1}, "force": {"LENGTH": 1, "MASS": 1, "TIME": -2}}


# ------------------------------------------------------------------------ the lab's own Test.Lab exports


def _drive_amplitude(x: np.ndarray, fs: float, f_guess: float) -> tuple[float, float]:
    """(frequency (Hz), amplitude) of the sine near `f_guess` in `x`, by a lock-in refined over +-0.05 Hz."""
    t = np.arange(x.size) / fs
    grid = np.linspace(f_guess - 0.05, f_guess + 0.05, 201)
    amps = [2 * abs(np.mean(x * np.exp(-2j * np.pi * f * t))) for f in grid]
    k = int(np.argmax(amps))
    return float(grid[k]), float(amps[k])


@pytest.mark.skipif(not REAL.is_dir(), reason=f"the lab's real dwell exports are not at {REAL} "
                    "(../shared/real/, never committed: their licence differs)")
@pytest.mark.parametrize("f_drive", [16, 17, 18, 19, 20])
def test_real_dwell_laser_and_acc1_describe_one_motion(f_drive):
    """The laser (velocity, m/s) and Acc1 beside it (stored in MKS, labelled 'g') agree at the drive: |a| = 2 pi f |v|
    within 2 % over the steady dwell (20-50 s). Read as the label says (g), Acc1 would be 9.81 times the laser."""
    chans = {c.names[0]: c for c in lab_channels(REAL / f"Sine_{f_drive}Hz_Time.mat", "Test.Lab MAT")}
    acc, laser = chans["Time Acc1:+X"], chans["Time Laser:+X"]
    assert (acc.unit, acc.quantity) == ("m/s^2", "acceleration")
    assert (laser.unit, laser.quantity) == ("m/s", "velocity")
    fs = 1.0 / acc.dt
    assert fs == 1024.0 and laser.dt == acc.dt
    steady = slice(int(20 * fs), int(50 * fs))
    f, a = _drive_amplitude(acc.values[steady], fs, f_drive)
    v = _drive_amplitude(laser.values[steady], fs, f)[1]
    ratio = a / (2 * np.pi * f * v)
    print(f"{f_drive} Hz: Acc1 {a:.4g} m/s^2, laser {v:.4g} m/s x 2 pi f = {2 * np.pi * f * v:.4g} m/s^2, "
          f"ratio {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.02)


@pytest.mark.skipif(not REAL.is_dir(), reason=f"the lab's real dwell exports are not at {REAL}")
def test_real_dwell_laser_named_as_the_response_is_refused_as_a_velocity(tmp_path):
    """The contract's response is an acceleration: a laser vibrometer's channel is named as a velocity."""
    with pytest.raises(CampaignError) as info:
        from jointcal.io._lab_formats import read_lab_export
        read_lab_export(REAL / "Sine_18Hz_Time.mat", "voltage",
                        {"reference": "Time Acc2:+X", "response": "Time Laser:+X"}, "dwell18")
    _one_sentence(str(info.value), "Sine_18Hz_Time.mat", "channel 'Time Acc2:+X' is an acceleration in the file")


# ------------------------------------------------------------------------ Test.Lab structs written as Test.Lab does


def _quantity(label: str, factor: float, dims: dict[str, int] | None) -> dict:
    q = {"label": label, "unit_transformation": {"offset": 0.0, "factor": factor, "log_reference": 1.0},
         "info": "Data saved by Test.Lab in MKS"}
    if dims is not None:
        q["quantity_terms"] = np.array([{"num": float(dims.get(t, 0)), "den": 1.0, "quantity": t} for t in TERMS],
                                       dtype=object)
    return q


def write_testlab_mks(path: Path, t: np.ndarray, channels: dict[str, tuple[np.ndarray, dict]]) -> None:
    """One Test.Lab struct per channel ('Time_<name>'), values in SI, as Test.Lab's MATLAB export holds them."""
    dt = (t[-1] - t[0]) / (t.size - 1)
    scipy.io.savemat(path, {f"Time_{name.replace(' ', '_')}": {
        "x_values": {"start_value": float(t[0]), "increment": dt, "number_of_values": t.size,
                     "quantity": _quantity("s", 1.0, DIMS["time"])},
        "y_values": {"values": values, "quantity": q},
        "function_record": {"name": f"Time {name}", "type": "Signal"}} for name, (values, q) in channels.items()})


def _as_lab_run(campaign: Path, suffix: str, write) -> tuple[Path, dict, pd.DataFrame]:
    """The first run of `campaign` rewritten by `write(path, df)`, the manifest naming 'Time Drive'/'Time Acc'."""
    row = read_manifest(campaign / "manifest.csv").iloc[0].to_dict()
    df = read_run(campaign / row["file"], row)
    file = row["file"].replace(".csv.gz", suffix)
    write(campaign / file, df)
    (campaign / row["file"]).unlink()
    edit_manifest(campaign, lambda m: m.assign(
        file=m["file"].where(m["run_id"] != row["run_id"], file),
        reference_channel=np.where(m["run_id"] == row["run_id"], "Time Drive", ""),
        response_channel=np.where(m["run_id"] == row["run_id"], "Time Acc", "")))
    return campaign / file, read_manifest(campaign / "manifest.csv").iloc[0].to_dict(), df


def test_a_testlab_mks_export_on_a_voltage_campaign_is_read_in_g(voltage):
    """SI values labelled 'g' with the factor 1/9.80665: read as m/s^2, they are the CSV's g to rounding (the
    label read as the unit would make them 9.81 times)."""
    def write(path, df):
        write_testlab_mks(path, df["time_s"].to_numpy(), {
            "Drive": (df["drive_V"].to_numpy(), _quantity("V", 1.0, DIMS["voltage"])),
            "Acc": (df["response_accel_g"].to_numpy() * G_SI, _quantity("g", 1 / G_SI, DIMS["acceleration"]))})
    path, row, df = _as_lab_run(voltage, ".mat", write)
    got = read_run(path, row)
    np.testing.assert_allclose(got["response_accel_g"], df["response_accel_g"], rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(got["drive_V"], df["drive_V"])
    assert got.attrs["sources"]["response_accel_g"] == {"name": "Time Acc", "unit": "m/s^2", "by": "file"}
    assert (ingest_campaign(voltage)["flags"] == "").all()


@pytest.mark.parametrize("case, words", [
    ("label of another quantity", ["channel 'Time Acc' is labelled 'N', a force, but its quantity_terms (stored in "
                                   "MKS) make its values an acceleration in m/s^2",
                                   "correct the channel's label or its quantity in the export"]),
    ("factor against the label", ["channel 'Time Acc' is labelled 'g', but its unit_transformation.factor 1 does not "
                                  "convert m/s^2 (its MKS values) to 'g'", "correct the label or the factor"]),
    ("dimensions of a force", ["channel 'Time Acc' is a force in the file, but the response of this run "
                               "(response_accel_g) is an acceleration", "name the acceleration channel"]),
])
def test_a_testlab_label_that_disagrees_with_the_stored_quantity_is_named(voltage, case, words):
    q = {"label of another quantity": _quantity("N", 1.0, DIMS["acceleration"]),
         "factor against the label": _quantity("g", 1.0, DIMS["acceleration"]),
         "dimensions of a force": _quantity("N", 1.0, DIMS["force"])}[case]

    def write(path, df):
        write_testlab_mks(path, df["time_s"].to_numpy(), {
            "Drive": (df["drive_V"].to_numpy(), _quantity("V", 1.0, DIMS["voltage"])),
            "Acc": (df["response_accel_g"].to_numpy() * G_SI, q)})
    path, row, _ = _as_lab_run(voltage, ".mat", write)
    with pytest.raises(CampaignError) as info:
        read_run(path, row)
    _one_sentence(str(info.value), path.name, *words)


# ------------------------------------------------------------------------ UFF 58: exponents and data set 164

# units code -> (length factor, force factor) of data set 164: file units per SI unit (SI = file / factor)
UNIT_CODES = {1: (1.0, 1.0), 2: (1 / (12 * INCH_M), 1 / LBF_N), 5: (1e3, 1e3), 7: (1 / INCH_M, 1 / LBF_N),
              9: (250.0, 3.0)}


def write_uff_units(path: Path, df: pd.DataFrame, code: int | None, *, response_label: str = "NONE",
                    exponent: int = 1) -> None:
    """The drive (V, by its label) and the response in the length unit of units `code`, said by its exponents
    (length `exponent`, force 0; acceleration, type 12) and data set 164 (none when `code` is None), by pyuff."""
    length, force = UNIT_CODES[code or 1]
    t = df["time_s"].to_numpy()
    sets = [] if code is None else [pyuff.prepare_164(units_code=code, units_description=f"code {code}",
                                                      temp_mode=1, length=length, force=force, temp=1.0,
                                                      temp_offset=273.15)]
    for i, (name, values, kind, exp, lab) in enumerate((
            ("Time Drive", df["drive_V"].to_numpy(), 0, 0, "V"),
            ("Time Acc", df["response_accel_g"].to_numpy() * G_SI * length, 12, exponent, response_label))):
        sets.append(pyuff.prepare_58(
            binary=1, id1=name, func_type=1, rsp_node=i + 1, rsp_dir=3, ref_node=0, ref_dir=0, data=values, x=t,
            abscissa_spacing=1, abscissa_spec_data_type=17, abscissa_axis_units_lab="s", abscissa_len_unit_exp=0,
            abscissa_force_unit_exp=0, ordinate_spec_data_type=kind, ordinate_len_unit_exp=exp,
            ordinate_force_unit_exp=0, ordinate_temp_unit_exp=0, ordinate_axis_units_lab=lab,
            orddenom_spec_data_type=0, z_axis_spec_data_type=0))
    pyuff.UFF(str(path)).write_sets(sets, "add")


@pytest.mark.parametrize("code", [1, 2, 5, 7, 9, None])
def test_a_uff_response_said_only_by_its_exponents_and_data_set_164_is_read_right(voltage, code):
    """Voltage-driven (no check of the response's scale exists): an acceleration said by length exponent 1 in
    data set 164's system (SI, foot, mm, inch, a user's), or SI when the file has no 164, is the CSV's g."""
    path, row, df = _as_lab_run(voltage, ".uff", lambda p, d: write_uff_units(p, d, code))
    got = read_run(path, row)
    np.testing.assert_allclose(got["response_accel_g"], df["response_accel_g"], rtol=1e-12, atol=1e-15)
    assert got.attrs["sources"]["response_accel_g"]["unit"] == "m/s^2"
    assert (ingest_campaign(voltage)["flags"] == "").all()


def test_a_base_driven_uff_in_si_said_only_by_exponents_and_data_set_164_is_read_right(tmp_path):
    """Both accelerations in m/s^2 (length exponent 1, data set 164 SI, no label): formerly read as g, 9.81x, and
    caught only by the level check; now the CSV's g, no flag."""
    from tests._support.campaign import example_copy

    campaign = example_copy(tmp_path / "c", "first_01_1g_up", "first_07_2g_up")
    row = read_manifest(campaign / "manifest.csv").iloc[0].to_dict()
    df = read_run(campaign / row["file"], row)
    t = df["time_s"].to_numpy()
    sets = [pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1, length=1.0, force=1.0, temp=1.0,
                              temp_offset=273.15)]
    for i, (name, col) in enumerate((("Time Drive", "base_accel_g"), ("Time Acc", "response_accel_g"))):
        sets.append(pyuff.prepare_58(
            binary=1, id1=name, func_type=1, rsp_node=i + 1, rsp_dir=3, ref_node=0, ref_dir=0,
            data=df[col].to_numpy() * G_SI, x=t, abscissa_spacing=1, abscissa_spec_data_type=17,
            abscissa_axis_units_lab="s", ordinate_spec_data_type=12, ordinate_len_unit_exp=1,
            ordinate_force_unit_exp=0, ordinate_temp_unit_exp=0, ordinate_axis_units_lab="NONE",
            orddenom_spec_data_type=0, z_axis_spec_data_type=0))
    file = row["file"].replace(".csv.gz", ".uff")
    pyuff.UFF(str(campaign / file)).write_sets(sets, "add")
    edit_manifest(campaign, lambda m: m.assign(
        file=m["file"].where(m["run_id"] != row["run_id"], file),
        reference_channel=np.where(m["run_id"] == row["run_id"], "Time Drive", ""),
        response_channel=np.where(m["run_id"] == row["run_id"], "Time Acc", "")))
    got = read_run(campaign / file, read_manifest(campaign / "manifest.csv").iloc[0].to_dict())
    for col in ("base_accel_g", "response_accel_g"):
        np.testing.assert_allclose(got[col], df[col], rtol=1e-12, atol=1e-15)
    runs = ingest_campaign(campaign)
    assert (runs["flags"] == "").all()
    assert list(runs["response_units_check"].str.split(":").str[0]) == ["m/s^2 confirmed", "g confirmed"]


@pytest.mark.parametrize("code", [1, 5, 7])
def test_a_uff_acceleration_with_exponents_0_is_read_in_the_system_of_data_set_164(voltage, code):
    """pyuff's default exponents (0) on a type-12 record without a label, in a file with data set 164: the
    acceleration's dimensions (length / s^2) in that system, not the contract's g."""
    path, row, df = _as_lab_run(voltage, ".uff", lambda p, d: write_uff_units(p, d, code, exponent=0))
    np.testing.assert_allclose(read_run(path, row)["response_accel_g"], df["response_accel_g"], rtol=1e-12,
                               atol=1e-15)


def test_a_uff_label_that_disagrees_with_its_exponents_is_named(voltage):
    """Label 'g' on values that length exponent 1 and data set 164 (SI) make m/s^2: one of them is wrong."""
    path, row, _ = _as_lab_run(voltage, ".uff", lambda p, d: write_uff_units(p, d, 1, response_label="g"))
    with pytest.raises(CampaignError) as info:
        read_run(path, row)
    _one_sentence(str(info.value), path.name, "channel 'Time Acc' is labelled 'g', but its unit exponents and data "
                  "set 164 make its values m/s^2", "correct the channel's label or its unit in the export")


def test_a_uff_label_that_agrees_with_its_exponents_is_read(voltage):
    path, row, df = _as_lab_run(voltage, ".uff", lambda p, d: write_uff_units(p, d, 1, response_label="m/s^2"))
    np.testing.assert_allclose(read_run(path, row)["response_accel_g"], df["response_accel_g"], rtol=1e-12)
