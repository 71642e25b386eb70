"""A lab's own exports (jointcal.io._lab_formats through jointcal.io.read_run): UFF 58 written by pyuff,
TDMS written by npTDMS and a Test.Lab-style MATLAB struct read as the same record as the contract's CSV,
channels named by the manifest, units taken from the file and checked against the channel's role."""
from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import pyuff
import scipy.io
from nptdms import ChannelObject, GroupObject, TdmsWriter

from jointcal.io import CampaignError, ingest_campaign, read_manifest, read_run
from jointcal.measure.modal import measure_run
from jointcal.units import G_SI  # m/s^2 per g
from tests._support.campaign import edit_manifest, example_copy

EXAMPLE_RUN = "first_01_1g_up"
NAMES = {"base_accel_g": "Ctrl Z", "drive_V": "Amp out", "response_accel_g": "Slug Z"}
QUANTITY = {"base_accel_g": "Acceleration", "drive_V": "Voltage", "response_accel_g": "Acceleration"}
UFF_TYPE = {"base_accel_g": 12, "drive_V": 0, "response_accel_g": 12}  # UFF 58 specific data types


def write_uff(path: Path, df: pd.DataFrame, units: dict[str, str], *, binary: int = 1,
              types: dict[str, int] | None = None) -> None:
    """Each channel of `df` as one UFF 58 time record (ID line 1 its name, node i + 1, +Z), by pyuff's writer."""
    t = df["time_s"].to_numpy()
    sets = []
    for i, col in enumerate(c for c in df.columns if c != "time_s"):
        sets.append(pyuff.prepare_58(
            binary=binary, id1=NAMES[col], func_type=1, rsp_node=i + 1, rsp_dir=3, ref_node=0, ref_dir=0,
            data=df[col].to_numpy(), x=t, abscissa_spacing=1, abscissa_spec_data_type=17,
            abscissa_axis_units_lab="s", ordinate_spec_data_type={**UFF_TYPE, **(types or {})}[col],
            ordinate_axis_units_lab=units.get(col, "NONE"), orddenom_spec_data_type=0, z_axis_spec_data_type=0))
    pyuff.UFF(str(path)).write_sets(sets, "add")


def write_tdms(path: Path, df: pd.DataFrame, units: dict[str, str]) -> None:
    """Each channel of `df` as a TDMS waveform channel of group 'Run', by npTDMS's writer."""
    t = df["time_s"].to_numpy()
    dt = (t[-1] - t[0]) / (t.size - 1)
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([GroupObject("Run")] + [
            ChannelObject("Run", NAMES[c], df[c].to_numpy(),
                          properties={"wf_increment": dt, "wf_start_offset": float(t[0]),
                                      **({"unit_string": units[c]} if c in units else {})})
            for c in df.columns if c != "time_s"])


def write_testlab(path: Path, df: pd.DataFrame, units: dict[str, str]) -> None:
    """The channels of `df` as one Test.Lab-style struct 'Signal' (x_values / y_values / function_record)."""
    t = df["time_s"].to_numpy()
    cols = [c for c in df.columns if c != "time_s"]
    quantity = [{"label": QUANTITY[c], **({"unit": units[c]} if c in units else {})} for c in cols]
    scipy.io.savemat(path, {"Signal": {
        "x_values": {"start_value": float(t[0]), "increment": (t[-1] - t[0]) / (t.size - 1),
                     "number_of_values": t.size, "quantity": {"label": "Time", "unit": "s"}},
        "y_values": {"values": df[cols].to_numpy(), "quantity": quantity},
        "function_record": {"name": np.array([NAMES[c] for c in cols], dtype=object), "type": "Time"}}})


WRITERS = {".uff": write_uff, ".tdms": write_tdms, ".mat": write_testlab}


def _lab_campaign(src: Path, folder: Path, suffix: str, units: dict[str, str] | None = None,
                  scale: dict[str, float] | None = None) -> Path:
    """`src` with its first run rewritten as a lab export (channels times `scale`, labelled `units`)."""
    import shutil

    shutil.copytree(src, folder)
    man = read_manifest(folder / "manifest.csv")
    row = man.iloc[0]
    df = read_run(folder / row["file"], row)
    ref = next(c for c in df.columns if c not in ("time_s", "response_accel_g"))
    out = df.assign(**{c: df[c] * f for c, f in (scale or {}).items()})
    file = f"runs/{row['run_id']}{suffix}"
    WRITERS[suffix](folder / file, out, units or {})
    edit_manifest(folder, lambda m: m.assign(
        file=m["file"].where(m["run_id"] != row["run_id"], file),
        reference_channel=np.where(m["run_id"] == row["run_id"], NAMES[ref], ""),
        response_channel=np.where(m["run_id"] == row["run_id"], NAMES["response_accel_g"], "")))
    return folder


@pytest.fixture(scope="module")
def example_src(tmp_path_factory) -> Path:
    return example_copy(tmp_path_factory.mktemp("example") / "c", EXAMPLE_RUN)


@pytest.fixture(scope="module")
def reference_tables(example_src, voltage_source) -> dict[str, dict]:
    """The modal table of each campaign's first run, read from its contract CSV."""
    out = {}
    for name, src in (("base", example_src), ("voltage", voltage_source)):
        row = read_manifest(src / "manifest.csv").iloc[0].to_dict()
        out[name] = measure_run(read_run(src / row["file"], row), row)[2]
    return out


def _table(folder: Path) -> tuple[dict, pd.DataFrame]:
    row = read_manifest(folder / "manifest.csv").iloc[0].to_dict()
    df = read_run(folder / row["file"], row)
    return measure_run(df, row)[2], df


@pytest.mark.parametrize("kind", ["base", "voltage"])
@pytest.mark.parametrize("suffix", [".uff", ".tdms", ".mat"])
def test_one_record_in_every_format_gives_identical_modal_tables(tmp_path, example_src, voltage_source,
                                                                  reference_tables, kind, suffix):
    """A base-driven example run and a voltage-driven synthetic run, written in the contract's units."""
    src = example_src if kind == "base" else voltage_source
    units = {"base_accel_g": "g", "drive_V": "V", "response_accel_g": "g"}
    folder = _lab_campaign(src, tmp_path / "c", suffix, units)
    props, df = _table(folder)
    csv_row = read_manifest(src / "manifest.csv").iloc[0]
    expected = read_run(src / csv_row["file"], csv_row)
    for col in expected.columns[1:]:
        np.testing.assert_array_equal(df[col].to_numpy(), expected[col].to_numpy())
    # UFF 58 writes the increment with 6 significant digits (E13.5): 1/1024 s is 0.5 ppm off
    np.testing.assert_allclose(df["time_s"], expected["time_s"], rtol=1e-6, atol=1e-8)
    assert props.keys() == reference_tables[kind].keys()
    for key, value in reference_tables[kind].items():
        assert props[key] == value or (value != value and props[key] != props[key]), key
    assert df.attrs["sources"]["response_accel_g"] == {"name": "Slug Z", "unit": "g", "by": "file"}
    assert (ingest_campaign(folder)["flags"] == "").all()


@pytest.mark.parametrize("suffix", [".uff", ".tdms", ".mat"])
def test_units_are_taken_from_the_file(tmp_path, example_src, suffix):
    """m/s^2 and mV in the file's metadata become g and V; the values agree with the CSV to rounding."""
    folder = _lab_campaign(example_src, tmp_path / "c", suffix, {"base_accel_g": "m/s^2", "response_accel_g": "m/s2"},
                           {"base_accel_g": G_SI, "response_accel_g": G_SI})
    row = read_manifest(folder / "manifest.csv").iloc[0]
    df = read_run(folder / row["file"], row)
    expected = read_run(example_src / f"runs/{EXAMPLE_RUN}.csv.gz")
    for col in ("base_accel_g", "response_accel_g"):
        np.testing.assert_allclose(df[col], expected[col], rtol=1e-14, atol=1e-15)
    assert df.attrs["sources"]["response_accel_g"]["unit"] == "m/s^2"
    assert (ingest_campaign(folder)["flags"] == "").all()


def test_a_drive_in_millivolts_by_its_unit_string(tmp_path, voltage_source):
    folder = _lab_campaign(voltage_source, tmp_path / "c", ".tdms", {"drive_V": "mV", "response_accel_g": "g"},
                           {"drive_V": 1000.0})
    row = read_manifest(folder / "manifest.csv").iloc[0]
    got = read_run(folder / row["file"], row)["drive_V"]
    np.testing.assert_allclose(got, read_run(voltage_source / row["file"].replace(".tdms", ".csv.gz"))["drive_V"],
                               rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("suffix, listed", [(".uff", "'Ctrl Z', 'Slug Z'"), (".tdms", "'Ctrl Z', 'Slug Z'"),
                                            (".mat", "'Ctrl Z', 'Slug Z'")])
def test_a_wrong_channel_name_lists_the_channels_the_file_has(tmp_path, example_src, suffix, listed):
    folder = _lab_campaign(example_src, tmp_path / "c", suffix, {"base_accel_g": "g", "response_accel_g": "g"})
    edit_manifest(folder, lambda m: m.assign(response_channel="Slug Y"))
    with pytest.raises(CampaignError) as info:
        ingest_campaign(folder)
    msg = str(info.value)
    assert f"{EXAMPLE_RUN}{suffix}: it has no channel 'Slug Y' (named in response_channel of run '{EXAMPLE_RUN}')" \
        in msg and f"the file's channels are {listed}" in msg and "write one of them in response_channel" in msg, msg
    assert "\n" not in msg and msg.endswith(".")


def test_channels_are_found_by_other_names_the_file_gives(tmp_path, example_src):
    """UFF: the response DOF (node:+Z); TDMS: group/channel; any case."""
    for suffix, ref, resp in ((".uff", "1:+Z", "2:+z"), (".tdms", "Run/Ctrl Z", "slug z")):
        folder = _lab_campaign(example_src, tmp_path / suffix[1:], suffix, {"base_accel_g": "g"})
        edit_manifest(folder, lambda m: m.assign(reference_channel=ref, response_channel=resp))
        row = read_manifest(folder / "manifest.csv").iloc[0]
        assert list(read_run(folder / row["file"], row).columns) == ["time_s", "base_accel_g", "response_accel_g"]


@pytest.mark.parametrize("case, words", [
    ("force as response", ["channel 'Slug Z' is in N, a force, but the response of this run (response_accel_g) is "
                           "an acceleration", "name the acceleration channel in response_channel"]),
    ("unknown unit", ["channel 'Slug Z' has the unit 'furlong/fortnight^2', which jointcal does not read",
                      "export the channel in one of these units"]),
    ("no names", ["a TDMS file names its channels, and the manifest's reference_channel of run 'first_01_1g_up' is "
                  "empty (the file's channels: 'Ctrl Z', 'Slug Z')", "write the reference channel's name there"]),
])
def test_units_and_names_against_the_contract(tmp_path, example_src, case, words):
    units = {"base_accel_g": "g", "response_accel_g": {"force as response": "N", "unknown unit": "furlong/fortnight^2",
                                                       "no names": "g"}[case]}
    folder = _lab_campaign(example_src, tmp_path / "c", ".tdms", units)
    if case == "no names":
        edit_manifest(folder, lambda m: m.assign(reference_channel=""))
    with pytest.raises(CampaignError) as info:
        ingest_campaign(folder)
    assert all(w in str(info.value) for w in words), str(info.value)


def test_a_uff_force_record_named_as_the_base_is_refused(tmp_path, example_src):
    """UFF's specific data type 13 (excitation force) is not the base acceleration of a base-driven run."""
    folder = _lab_campaign(example_src, tmp_path / "c", ".uff", {"response_accel_g": "g"})
    path = folder / f"runs/{EXAMPLE_RUN}.uff"
    path.unlink()
    write_uff(path, read_run(example_src / f"runs/{EXAMPLE_RUN}.csv.gz"), {"response_accel_g": "g"},
              types={"base_accel_g": 13})
    with pytest.raises(CampaignError, match="channel 'Ctrl Z' is a force in the file, but the reference of this run "
                                            r"\(base_accel_g\) is an acceleration"):
        ingest_campaign(folder)


def test_a_channel_without_a_unit_is_read_in_the_contract_unit_and_the_base_check_still_applies(
        tmp_path, example_src):
    """No unit in the file: g is assumed; a response that is in m/s^2 is still caught, base-driven."""
    folder = _lab_campaign(example_src, tmp_path / "c", ".uff", {}, {"response_accel_g": G_SI})
    with pytest.warns(Warning) as record:
        runs = ingest_campaign(folder, on_data_problem="flag")
    assert runs.loc[0, "flags"] == "units:response_accel_g"
    msg = str(record[0].message)
    assert "the response read from 'Slug Z' as g" in msg and "give channel 'Slug Z' its unit in the file" in msg


def test_channels_named_for_a_csv_record_are_refused(tmp_path, example_src):
    import shutil

    folder = Path(shutil.copytree(example_src, tmp_path / "c"))
    edit_manifest(folder, lambda m: m.assign(reference_channel="Ctrl Z", response_channel="Slug Z"))
    with pytest.raises(CampaignError, match="the manifest names channels \\(Ctrl Z, Slug Z\\) for a CSV record"):
        ingest_campaign(folder)


def test_two_channels_with_different_time_axes_are_refused(tmp_path, example_src):
    folder = _lab_campaign(example_src, tmp_path / "c", ".tdms", {"base_accel_g": "g", "response_accel_g": "g"})
    path = folder / f"runs/{EXAMPLE_RUN}.tdms"
    df = read_run(example_src / f"runs/{EXAMPLE_RUN}.csv.gz")
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([GroupObject("Run"),
                              ChannelObject("Run", "Ctrl Z", df["base_accel_g"].to_numpy(),
                                            properties={"wf_increment": 1 / 12800, "unit_string": "g"}),
                              ChannelObject("Run", "Slug Z", df["response_accel_g"].to_numpy()[::2],
                                            properties={"wf_increment": 2 / 12800, "unit_string": "g"})])
    with pytest.raises(CampaignError, match="channels 'Ctrl Z' and 'Slug Z' have different time axes"):
        ingest_campaign(folder)


def test_a_uff_ascii_export_reads_the_same_numbers(tmp_path, example_src):
    """pyuff's ASCII data-set 58 (12 significant digits) holds the CSV's 9 exactly."""
    folder = tmp_path / "c"
    _lab_campaign(example_src, folder, ".uff", {"base_accel_g": "g", "response_accel_g": "g"})
    row = read_manifest(folder / "manifest.csv").iloc[0]
    path = folder / row["file"]
    df = read_run(example_src / f"runs/{EXAMPLE_RUN}.csv.gz")
    path.unlink()
    write_uff(path, df, {"base_accel_g": "g", "response_accel_g": "g"}, binary=0)
    pd.testing.assert_frame_equal(read_run(path, row)[["base_accel_g", "response_accel_g"]],
                                  df[["base_accel_g", "response_accel_g"]], check_exact=True)


def test_a_file_that_is_not_its_format_is_one_sentence(tmp_path, example_src):
    folder = _lab_campaign(example_src, tmp_path / "c", ".tdms", {"base_accel_g": "g", "response_accel_g": "g"})
    (folder / f"runs/{EXAMPLE_RUN}.tdms").write_bytes(gzip.compress(b"time_s,base_accel_g\n"))
    with pytest.raises(CampaignError, match="cannot be read as a TDMS file"):
        ingest_campaign(folder)


def test_a_lab_export_read_without_its_manifest_row_says_so(tmp_path, example_src):
    folder = _lab_campaign(example_src, tmp_path / "c", ".uff", {"base_accel_g": "g", "response_accel_g": "g"})
    with pytest.raises(CampaignError, match="a UFF 58 record needs its manifest row"):
        read_run(folder / f"runs/{EXAMPLE_RUN}.uff")
