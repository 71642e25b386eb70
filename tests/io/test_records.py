"""Records and campaigns (jointcal.io._records): the contract's CSV and MAT read back exactly, a
campaign ingested against a known sweep, and every malformed record or manifest one sentence naming the file."""
from __future__ import annotations

import importlib.util
import shutil
import warnings

import numpy as np
import pandas as pd
import pytest
import scipy.io

from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, listed_record, read_run, write_run
from tests._support.campaign import DATA, edit_manifest, edit_run
from tests._support.ingest import _stopped, _write_csv


# ------------------------------------------------------------------------ readers


@pytest.mark.parametrize("suffix", [".csv", ".csv.gz", ".mat"])
def test_formats_read_identical_arrays(tmp_path, small_campaign, suffix):
    ref = read_run(small_campaign / "run01.csv.gz")
    out = write_run(tmp_path / f"copy{suffix}", *(ref[c] for c in ref.columns))
    got = read_run(out)
    assert list(got.columns) == ["time_s", "base_accel_g", "response_accel_g"]
    assert (got.dtypes == np.float64).all()
    pd.testing.assert_frame_equal(got, ref, check_exact=True)


def test_mat_row_vectors_and_extra_variables(tmp_path, small_campaign):
    ref = read_run(small_campaign / "run05.mat")
    cols = {c: ref[c].to_numpy()[None, :] for c in ref.columns}  # 1 x n row vectors
    scipy.io.savemat(tmp_path / "row.mat", {**cols, "operator": "jd"})
    pd.testing.assert_frame_equal(read_run(tmp_path / "row.mat"), ref, check_exact=True)


def test_force_driven_round_trip(tmp_path):
    t = np.arange(100) / 1000.0
    got = read_run(write_run(tmp_path / "f.csv", t, np.sin(t), np.cos(t), kind="force"))
    assert list(got.columns) == ["time_s", "force_lbf", "response_accel_g"]
    np.testing.assert_allclose(got["force_lbf"], np.sin(t), rtol=1e-8)


def test_committed_campaign_matches_generator(tmp_path, small_campaign):
    spec = importlib.util.spec_from_file_location("make_small_campaign", DATA / "make_small_campaign.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    manifest = gen.make(tmp_path)
    assert (small_campaign / "manifest.csv").read_text() == (tmp_path / "manifest.csv").read_text()
    for file in manifest["file"]:
        np.testing.assert_allclose(read_run(tmp_path / file), read_run(small_campaign / file), rtol=1e-7, atol=1e-9)
    assert sum(f.stat().st_size for f in small_campaign.iterdir()) < 1.5e6


# ------------------------------------------------------------------------ validation, known truth


def test_clean_campaign_recovers_known_sweep(small_campaign):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        runs = ingest_campaign(small_campaign)
    assert len(runs) == 5 and (runs["flags"] == "").all()
    assert (runs["excitation"] == "base").all() and runs["rms_force_lbf"].isna().all()
    np.testing.assert_allclose(runs["fs_measured_hz"], 12800.0, rtol=1e-9)
    np.testing.assert_allclose(runs["f_first_hz"], runs["f_start_hz"], atol=5.0)  # Hz; tolerance is ~63 Hz
    np.testing.assert_allclose(runs["f_last_hz"], runs["f_stop_hz"], atol=5.0)
    # a 0.7 s sweep of amplitude level in a 0.75 s record: rms = level / sqrt(2) * sqrt(0.7 / 0.75)
    expected = runs["level_g"] / np.sqrt(2) * np.sqrt(0.7 / 0.75)
    np.testing.assert_allclose(runs["rms_base_accel_g"], expected, rtol=0.02)


# ------------------------------------------------------------------------ malformed campaigns


def _clip(df, col="response_accel_g", frac=0.25):
    limit = frac * df[col].abs().max()
    df[col] = df[col].clip(-limit, limit)


def _stick(df, col="base_accel_g"):
    i = int(df[col].to_numpy().argmax())
    df.loc[i:i + 2, col] = df[col].iloc[i]  # one run of exactly 3 samples at the maximum


def _set(df, i, col, value):
    df.loc[i, col] = value
    return df


def _swap_times(df):
    df.loc[100, "time_s"], df.loc[101, "time_s"] = df.loc[101, "time_s"], df.loc[100, "time_s"]


def _row(df, rid, **values):
    for col, value in values.items():
        df.loc[df["run_id"] == rid, col] = value


RUN_CASES = {  # name: (file to edit, edit of its table, words the message must contain)
    "missing column": ("run03.csv.gz", lambda d: d.drop(columns="response_accel_g"),
                       ["run03.csv.gz", "'response_accel_g' is missing"]),
    "wrong column": ("run03.csv.gz", lambda d: d.rename(columns={"base_accel_g": "base_g"}),
                     ["run03.csv.gz", "base_accel_g"]),
    "extra column": ("run02.csv.gz", lambda d: d.assign(temp_c=20.0), ["run02.csv.gz", "temp_c"]),
    "non-numeric": ("run02.csv.gz", lambda d: _set(d.astype({"base_accel_g": object}), 7, "base_accel_g", "1.2.3"),
                    ["run02.csv.gz", "1.2.3", "line 9"]),
    "non-monotonic time": ("run01.csv.gz", _swap_times, ["run01.csv.gz", "does not increase"]),
    "time gap": ("run01.csv.gz", lambda d: d.drop(index=range(200, 210)), ["run01.csv.gz", "jumps"]),
    "nan": ("run04.csv.gz", lambda d: _set(d, 500, "response_accel_g", np.nan), ["run04.csv.gz", "NaN"]),
    "inf": ("run04.csv.gz", lambda d: _set(d, 50, "base_accel_g", np.inf), ["run04.csv.gz", "NaN/inf"]),
    "clipped, many runs": ("run01.csv.gz", _clip, ["run01.csv.gz", "clipped"]),
    "clipped, one run": ("run02.csv.gz", _stick, ["run02.csv.gz", "clipped (3 samples at"]),
    "truncated": ("run03.csv.gz", lambda d: d.iloc[:5000], ["run03.csv.gz", "lasts"]),
}
MANIFEST_CASES = {  # name: (edit of the manifest, words the message must contain)
    "wrong sample rate": (lambda m: _row(m, "run02", sample_rate_hz="12700"), ["run02.csv.gz", "sample_rate_hz"]),
    "band too long": (lambda m: _row(m, "run01", f_start_hz="1000"), ["run01.csv.gz", "lasts"]),
    "band shifted": (lambda m: _row(m, "run01", f_start_hz="1800", f_stop_hz="3200"),
                     ["run01.csv.gz", "drive frequency at the sweep start"]),
    "direction swapped": (lambda m: _row(m, "run03", direction="down", f_start_hz="2900", f_stop_hz="1500"),
                          ["run03.csv.gz", "drive frequency"]),
    "rate wrong": (lambda m: _row(m, "run01", f_stop_hz="2200", sweep_rate_hz_per_s="1000"),
                   ["run01.csv.gz", "drive frequency at the sweep end"]),
    "force vs base": (lambda m: m.rename(columns={"level_g": "level_lbf"}), ["run01.csv.gz", "level_lbf"]),
    "bad direction": (lambda m: _row(m, "run02", direction="sideways"), ["manifest.csv", "line 3", "sideways"]),
    "direction vs band": (lambda m: _row(m, "run02", direction="up"), ["manifest.csv", "run02", "an up sweep"]),
    "duplicate run_id": (lambda m: _row(m, "run04", run_id="run03"), ["manifest.csv", "lines 4, 5", "run_id"]),
    "duplicate sequence": (lambda m: _row(m, "run04", sequence="1"), ["manifest.csv", "lines 2, 5", "sequence 1"]),
    "sequence zero": (lambda m: _row(m, "run04", sequence="0"), ["manifest.csv", "run04", "sequence"]),
    "negative rate": (lambda m: _row(m, "run01", sweep_rate_hz_per_s="-2000"),
                      ["manifest.csv", "sweep_rate_hz_per_s"]),
    "text level": (lambda m: _row(m, "run01", level_g="one"), ["manifest.csv", "level_g", "'one'"]),
    "empty cell": (lambda m: _row(m, "run05", assembly=""), ["manifest.csv", "run05", "assembly is empty"]),
    "above nyquist": (lambda m: _row(m, "run01", sample_rate_hz="5000"), ["manifest.csv", "Nyquist"]),
    "missing manifest column": (lambda m: m.drop(columns="file"), ["manifest.csv", "file"]),
    "both levels": (lambda m: m.assign(level_lbf="1"), ["manifest.csv", "level_lbf"]),
}


def _raises_naming(campaign, words):
    with pytest.raises(CampaignError) as info:
        ingest_campaign(campaign)
    msg = str(info.value)
    assert all(w in msg for w in words), msg
    assert "\n" not in msg and msg.endswith(".")
    return msg


@pytest.mark.parametrize("name", RUN_CASES)
def test_malformed_run_raises_naming_file(campaign, name):
    file, edit, words = RUN_CASES[name]
    edit_run(campaign, file, edit)
    _raises_naming(campaign, words)


@pytest.mark.parametrize("name", MANIFEST_CASES)
def test_malformed_manifest_raises_naming_file(campaign, name):
    edit, words = MANIFEST_CASES[name]
    edit_manifest(campaign, edit)
    _raises_naming(campaign, words)


def test_missing_run_file(campaign):
    (campaign / "run02.csv.gz").unlink()
    _raises_naming(campaign, ["run02.csv.gz", "does not exist"])


def test_unsupported_suffix(campaign):
    (campaign / "run02.csv.gz").rename(campaign / "run02.txt")
    edit_manifest(campaign, lambda m: _row(m, "run02", file="run02.txt"))
    _raises_naming(campaign, ["run02.txt", "unsupported file type"])


def test_missing_manifest(campaign):
    (campaign / "manifest.csv").unlink()
    _raises_naming(campaign, ["manifest.csv", "does not exist"])


def test_mat_missing_variable(campaign):
    mat = {k: v for k, v in scipy.io.loadmat(campaign / "run05.mat").items() if not k.startswith("__")}
    mat["resp"] = mat.pop("response_accel_g")
    scipy.io.savemat(campaign / "run05.mat", mat)
    _raises_naming(campaign, ["run05.mat", "'response_accel_g' is missing"])


def test_flag_mode_records_data_problems(campaign):
    edit_run(campaign, "run04.csv.gz", RUN_CASES["nan"][1])
    edit_run(campaign, "run01.csv.gz", _clip)
    with pytest.warns(CampaignWarning) as record:
        runs = ingest_campaign(campaign, on_data_problem="flag").set_index("run_id")
    assert runs.loc["run04", "flags"] == "nonfinite:response_accel_g"
    assert runs.loc["run01", "flags"] == "clipped:response_accel_g"
    assert (runs.drop(index=["run01", "run04"])["flags"] == "").all()
    assert np.isfinite(runs.loc["run04", "rms_response_accel_g"])
    messages = [str(w.message) for w in record]
    assert any("run04.csv.gz" in m and "NaN" in m for m in messages)
    assert any("run01.csv.gz" in m and "clipped" in m for m in messages)


def test_flag_mode_still_raises_structural_problems(campaign):
    edit_run(campaign, "run01.csv.gz", _swap_times)
    with pytest.raises(CampaignError, match="run01.csv.gz"):
        ingest_campaign(campaign, on_data_problem="flag")


def test_duplicate_basenames_keep_their_own_records(campaign):
    """Two folders may hold files of one name: each run gets its own record."""
    for rid, folder in (("run01", "a"), ("run02", "b")):
        (campaign / folder).mkdir()
        shutil.move(campaign / f"{rid}.csv.gz", campaign / folder / "run.csv.gz")
        edit_manifest(campaign, lambda m, r=rid, f=folder: m.assign(
            file=m["file"].where(m["run_id"] != r, f"{f}/run.csv.gz")))
    runs = ingest_campaign(campaign).set_index("run_id")
    assert runs.loc["run01", "f_first_hz"] < 1600 < runs.loc["run02", "f_first_hz"]  # up vs down: each its own file
    paths = [str(campaign / f) for f in runs["file"]]
    assert listed_record("a/run.csv.gz", paths) == str(campaign / "a" / "run.csv.gz")
    assert listed_record("b/run.csv.gz", paths) == str(campaign / "b" / "run.csv.gz")
    assert listed_record("a/run.csv.gz", [str(campaign / "b" / "a" / "run.csv.gz"), paths[0]]) == paths[0]


def test_a_mat_file_with_other_variable_names_lists_them(voltage, capsys):
    rid = "beam_01_0.3V_up"
    df = read_run(voltage / "runs" / f"{rid}.csv.gz")
    scipy.io.savemat(voltage / "runs" / f"{rid}.mat", {"t": df["time_s"].to_numpy(), "volts": df["drive_V"].to_numpy(),
                                                       "acc": df["response_accel_g"].to_numpy()})
    edit_manifest(voltage, lambda m: m.assign(file=m["file"].where(m["run_id"] != rid, f"runs/{rid}.mat")))
    msg = _stopped(voltage, capsys, f"{rid}.mat: variable 'time_s' is missing", "(the file's variables: t, volts, acc)",
                   "save the MAT variables time_s,drive_V,response_accel_g")
    assert "base_accel_g" not in msg and "column" not in msg


def test_a_mat_file_without_the_drive_names_the_voltage_channel(voltage, capsys):
    rid = "beam_01_0.3V_up"
    df = read_run(voltage / "runs" / f"{rid}.csv.gz")
    scipy.io.savemat(voltage / "runs" / f"{rid}.mat", {"time_s": df["time_s"].to_numpy(),
                                                       "response_accel_g": df["response_accel_g"].to_numpy()})
    edit_manifest(voltage, lambda m: m.assign(file=m["file"].where(m["run_id"] != rid, f"runs/{rid}.mat")))
    _stopped(voltage, capsys, "variable 'drive_V' (the manifest's level_V makes the run voltage-driven) is missing",
             "(the file's variables: time_s, response_accel_g)")


@pytest.mark.parametrize("cols, words", [
    (["time_s", "drive_V", "force_lbf", "response_accel_g"], ["2 reference channels", "drive_V"]),
    (["time_s", "drive_V", "response_accel_g", "response_accel_m_s2"], ["unexpected", "response_accel_m_s2"]),
    (["time_s", "drive_V"], ["response_accel_g", "response_accel_m_s2"]),
])
def test_reference_and_response_columns_are_checked(tmp_path, cols, words):
    _write_csv(tmp_path / "r.csv", {c: np.arange(20.0) for c in cols})
    with pytest.raises(CampaignError) as exc:
        read_run(tmp_path / "r.csv")
    assert all(w in str(exc.value) for w in words), str(exc.value)


def test_voltage_record_round_trip(tmp_path):
    t = np.arange(100) / 1000.0
    write_run(tmp_path / "v.mat", t, np.sin(t), np.cos(t), kind="voltage")
    df = read_run(tmp_path / "v.mat")
    assert list(df.columns) == ["time_s", "drive_V", "response_accel_g"]
    np.testing.assert_allclose(df["drive_V"], np.sin(t))
