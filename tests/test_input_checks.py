"""Input checks that catch what changes answers: each bad input gets one sentence
naming the file, the problem and the fix; data problems are flags that keep the run out of
the calibration; contract violations stop the run, leaving no output behind."""
from __future__ import annotations

import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from jointcal.calibrate.data import select_modal
from jointcal.cli import main
from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, listed_record, read_run, validate_run
from jointcal.io._clipping import clip_levels, clipped_mask
from tests._support.campaign import REPO, edit_manifest, edit_run
from tests._support.ingest import _set, _si


def _one_sentence(msg: str, *words: str) -> None:
    assert all(w in msg for w in words), msg
    assert "\n" not in msg and msg.endswith((".", "?")), msg


def _flag(campaign: Path, rid: str, *words: str) -> list[str]:
    """Ingest under 'flag': the run's flags; under 'error': one sentence naming the words."""
    with pytest.warns(CampaignWarning) as record:
        runs = ingest_campaign(campaign, on_data_problem="flag").set_index("run_id")
    msgs = [str(w.message) for w in record if issubclass(w.category, CampaignWarning)]
    assert any(all(w in m for w in words) for m in msgs), msgs
    with pytest.raises(CampaignError) as info:
        ingest_campaign(campaign)
    _one_sentence(str(info.value), *words)
    return runs.loc[rid, "flags"].split(";")


def _raises(campaign: Path, *words: str) -> str:
    with pytest.raises(CampaignError) as info:
        ingest_campaign(campaign, on_data_problem="flag")
    _one_sentence(str(info.value), *words)
    return str(info.value)


# ------------------------------------------------------------------------ clipping


def _sdof_sweep(fs: float, *, level: float = 1.0, fn: float = 2200.0, zeta: float = 0.02, rate: float = 2000.0,
                band: tuple[float, float] = (1800.0, 2600.0), seed: int = 7):
    """A linear SDOF base-excited sweep (exact for piecewise-linear input, scipy.signal.lsim).

    Returns time (s), base (g), absolute response (g) with 0.3 % noise, and the response's
    peak at resonance (g). Units g, s, Hz.
    """
    rng = np.random.default_rng(seed)
    f0, f1 = band
    sweep_s = (f1 - f0) / rate
    t = np.arange(int(round((sweep_s + 0.02) * fs))) / fs
    tt = np.minimum(t, sweep_s)
    base = level * np.sin(2 * np.pi * (f0 * tt + 0.5 * rate * tt**2)) * (t < sweep_s)
    w = 2 * np.pi * fn
    sdof = signal.StateSpace([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [-1.0]], [[-w * w, -2 * zeta * w]], [[0.0]])
    _, resp, _ = signal.lsim(sdof, base, t)
    base = base + 0.003 * level * rng.standard_normal(t.size)
    resp = resp + 0.003 * np.std(resp) * rng.standard_normal(t.size)
    return t, base, resp, float(np.abs(resp).max())


def _adc(x: np.ndarray, full_scale: float, bits: int = 24) -> np.ndarray:
    """A DAQ's ADC: quantised to `bits`, clipped at +/- full_scale (unit of x), as jointcal.synth.daq."""
    lsb = 2.0 * full_scale / 2**bits
    return np.clip(np.round(x / lsb), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * lsb


def _row(fs: float, band=(1800.0, 2600.0), rate=2000.0) -> dict:
    return {"run_id": "r1", "assembly": "a", "sequence": 1, "level_g": 1.0, "direction": "up",
            "f_start_hz": band[0], "f_stop_hz": band[1], "sweep_rate_hz_per_s": rate, "sample_rate_hz": fs,
            "file": "r1.csv"}


def _longest_flat_top(x: np.ndarray) -> int:
    at = np.r_[0, (x == x.max()).astype(np.int8), 0]
    edges = np.diff(at)
    return int((np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)).max())


@pytest.mark.parametrize("fs", [12800.0, 25600.0])
@pytest.mark.parametrize("frac", [0.6, 0.8, 0.95])
def test_clipping_at_a_fraction_of_the_resonance_peak_is_flagged(fs, frac):
    t, base, resp, peak = _sdof_sweep(fs)
    clipped = _adc(resp, frac * peak)  # the response channel's input range is frac x its peak
    df = pd.DataFrame({"time_s": t, "base_accel_g": _adc(base, 4.0), "response_accel_g": clipped})
    if fs == 12800.0:  # flat tops of 1-2 samples: the old ">= 3 consecutive" rule missed these
        assert _longest_flat_top(clipped) <= 2
    with pytest.warns(CampaignWarning) as record:
        checks = validate_run(df, _row(fs), "lab/r1.csv", on_data_problem="flag")
    assert checks["flags"] == ["clipped:response_accel_g"]
    msg = str(record[0].message)
    _one_sentence(msg, "lab/r1.csv", "'response_accel_g' is clipped", f"at {frac * peak:.6g}",
                  "repeat the run with a wider input range or a lower level")
    # the envelopes leave out exactly the samples at the clipped extremes
    mask = clipped_mask(clipped)
    np.testing.assert_array_equal(mask, np.isclose(np.abs(clipped), np.abs(clipped).max(), rtol=0, atol=1e-6 * peak))
    with pytest.raises(CampaignError, match="is clipped"):
        validate_run(df, _row(fs), "lab/r1.csv")
    clean = df.assign(response_accel_g=_adc(resp, 2.0 * peak))  # same run, input range 2x the peak
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert validate_run(clean, _row(fs), "lab/r1.csv")["flags"] == []


@pytest.mark.parametrize("bits", [24, 16, 12])
def test_clean_quantised_sweeps_are_not_clipped(bits):
    """A noisy sweep's extreme sample is unique: no pile-up, whatever the ADC's resolution."""
    t, base, resp, peak = _sdof_sweep(12800.0, seed=bits)
    for x, fsc in ((base, 2.0), (resp, 1.5 * peak)):
        assert clip_levels(_adc(x, fsc, bits)) == []


def test_noiseless_synthetic_references_are_not_clipped():
    """A float chirp or tone at a rational frequency hits its crest exactly on many samples
    (sin rounds to 1 within 1e-8 rad): no pile-up against the samples just below or mid-range."""
    fs = 25600.0
    t = np.arange(int(0.5 * fs)) / fs
    for x in (17.79 * np.sin(2 * np.pi * (1600 * t + 0.5 * 1000 * t**2)),  # 5 samples exactly at the crest
              np.sin(2 * np.pi * 1600 * t), np.sin(2 * np.pi * 1000 * t)):  # every value repeats
        assert clip_levels(x) == [] and not clipped_mask(x).any()


def test_committed_campaigns_raise_no_flag():
    """No false positive on the example campaign (24-bit, noise, ripple) or the small one."""
    for campaign in (REPO / "raw_data", REPO / "tests" / "data" / "small_campaign"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            runs = ingest_campaign(campaign)
        assert (runs["flags"] == "").all()


def test_silent_dropout_is_not_clipping(small_campaign):
    df = read_run(small_campaign / "run01.csv.gz")
    df.loc[3000:3400, "response_accel_g"] = 0.0
    assert clip_levels(df["response_accel_g"].to_numpy()) == []


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


def test_level_mistakes_are_left_out_of_the_calibration():
    """A run flagged for its units, level or channels at ingest never enters the fit."""
    modal = pd.DataFrame({"run_id": ["r1", "r2", "r3", "r4"], "assembly": "first", "q_in": [1e-4, 2e-4, 1e-3, 3e-4],
                          "f_res_hz": 2000.0, "zeta_phase_resonance": 0.01, "zeta_res": 0.01,
                          "level_g": [1.0, 1.0, 1.0, 2.0],
                          "flags": ["", "level:base_accel_g", "swapped:base_accel_g;bad_samples",
                                    "clipped:response_accel_g"]})
    data = select_modal(modal, "first")
    assert data.run_id == ("r1",)  # clipped: the peak is missing, damping biased high (see below)


@pytest.mark.parametrize("col", ["response_accel_g", "base_accel_g"])
def test_zero_channel_is_named(campaign, col):
    edit_run(campaign, "run02.csv.gz", _set(col, 0.0))
    flags = _flag(campaign, "run02", "run02.csv.gz", f"'{col}' is constant at 0 (no signal recorded)",
                  "check the sensor, its cable")
    assert flags == [f"constant:{col}"]


def test_all_nan_base_is_reported_as_nan_not_as_a_wrong_sweep(campaign):
    edit_run(campaign, "run02.csv.gz", _set("base_accel_g", np.nan))
    flags = _flag(campaign, "run02", "run02.csv.gz", "'base_accel_g' has 9600 NaN/inf values")
    assert flags == ["nonfinite:base_accel_g"]


def test_swapped_columns_are_named(campaign):
    def swap(d):
        d[["base_accel_g", "response_accel_g"]] = d[["response_accel_g", "base_accel_g"]].to_numpy()
    edit_run(campaign, "run04.csv.gz", swap)
    flags = _flag(campaign, "run04", "run04.csv.gz", "the two columns look swapped",
                  "export each channel under its own name")
    assert flags == ["swapped:base_accel_g"]


# ------------------------------------------------------------------------ contract: names, delimiters, time units


@pytest.mark.parametrize("rid, bad", [("first/run02", "'/'"), ("run 02", "' '"), ("../run02", "'/'")])
def test_run_id_must_be_a_safe_file_name(campaign, rid, bad):
    edit_manifest(campaign, lambda m: m.assign(run_id=m["run_id"].where(m["run_id"] != "run02", rid)))
    _raises(campaign, "manifest.csv: line 3", f"run_id {rid!r} is not a safe file name", bad,
            "use letters, digits")


@pytest.mark.parametrize("sep, name", [(";", "semicolons"), ("\t", "tabs")])
def test_manifest_delimiter_is_guessed_and_named(campaign, sep, name):
    m = pd.read_csv(campaign / "manifest.csv", dtype=str)
    m.to_csv(campaign / "manifest.csv", sep=sep, index=False, decimal=",")
    _raises(campaign, "manifest.csv", f"separated by {name}", "save it as comma-separated text")


def test_run_file_delimiter_is_guessed_and_named(campaign):
    read_run(campaign / "run03.csv.gz").to_csv(campaign / "run03.csv.gz", sep=";", index=False, decimal=",")
    _raises(campaign, "run03.csv.gz", "separated by semicolons", "save it as comma-separated text")


@pytest.mark.parametrize("scale, unit, fix", [(1e3, "milliseconds", "multiply by 0.001"),
                                              (1e6, "microseconds", "multiply by 1e-06"),
                                              (12800.0, "sample numbers", "multiply by 7.8125e-05")])
def test_time_unit_is_guessed_and_named(campaign, scale, unit, fix):
    def rescale(d):
        d["time_s"] = d["time_s"] * scale
    edit_run(campaign, "run01.csv.gz", rescale)
    _raises(campaign, "run01.csv.gz", f"means it is written in {unit}", f"export time_s in seconds ({fix})")


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


# ------------------------------------------------------------------------ command line


def test_ingest_refuses_to_overwrite_an_input(campaign, capsys):
    before = (campaign / "manifest.csv").read_bytes()
    assert main(["ingest", str(campaign), str(campaign / "manifest.csv")]) == 2
    err = capsys.readouterr().err
    _one_sentence(err.strip(), "manifest.csv: OUT_CSV is an input of the campaign", "write the table elsewhere")
    assert (campaign / "manifest.csv").read_bytes() == before
    assert main(["ingest", str(campaign), str(campaign / "run05.mat")]) == 2


def test_ingest_to_a_folder_is_one_sentence(campaign, capsys):
    assert main(["ingest", str(campaign), str(campaign)]) == 2
    err = capsys.readouterr().err
    _one_sentence(err.strip(), "OUT_CSV is a folder", "runs.csv")
    assert "Traceback" not in err


def test_cli_keeps_the_warnings_before_an_error(tmp_path, campaign):
    edit_run(campaign, "run01.csv.gz", _set("base_accel_g", np.nan))
    edit_run(campaign, "run03.csv.gz", lambda d: d.drop(columns="response_accel_g"))
    out = tmp_path / "runs.csv"
    res = subprocess.run([sys.executable, "-m", "jointcal.cli", "ingest", str(campaign), str(out),
                          "--on-data-problem", "flag"], capture_output=True, text=True)
    lines = res.stderr.splitlines()
    assert res.returncode == 2 and len(lines) == 2 and "Traceback" not in res.stderr
    assert lines[0].startswith("jointcal: warning: ") and "run01.csv.gz" in lines[0] and "NaN" in lines[0]
    assert lines[1].startswith("jointcal: ") and "run03.csv.gz" in lines[1]
    assert not out.exists()


@pytest.mark.parametrize("text, words", [
    ("seed: 1\nsweep:\n  f_start_hz: 700\n f_stop_hz: 900\n", ["not valid YAML at line 4", "fix the syntax there"]),
    ("seed: 1\nseries:\n  level_g: 1.0\n  repeats: 1\n", ["series must be a list", "DEFAULT_SPEC"]),
    ("seed: 1\nseries: [1.0]\n", ["series item 1 must be a mapping", "level_g: 1.0"]),
    ("seed: 1\nsweep: 700\n", ["sweep must be a mapping of keys"]),
    ('{"seed": 1,}', ["not valid JSON at line 1", "fix the syntax there"]),
])
def test_malformed_synth_spec_is_one_sentence(tmp_path, capsys, text, words):
    spec = tmp_path / ("spec.json" if text.startswith("{") else "spec.yaml")
    spec.write_text(text)
    out = tmp_path / "camp"
    assert main(["synth", str(spec), str(out), "--truth", str(tmp_path / "truth.json")]) == 2
    err = capsys.readouterr().err.strip()
    _one_sentence(err, str(spec), *words)
    assert not out.exists() and not (tmp_path / "truth.json").exists()


def test_clipped_runs_stay_out_of_the_fit_because_leaving_frames_out_does_not_save_the_damping():
    """Why `clipped` is in UNUSABLE_FLAGS: with the clipped frames left out, the resonance peak is
    missing and the damping of a linear SDOF (zeta 0.02) clipped at 60 % of its peak comes out far high."""
    from jointcal.measure.modal import measure_run

    t, base, resp, peak = _sdof_sweep(12800.0)
    zeta = {}
    for frac in (2.0, 0.6):
        df = pd.DataFrame({"time_s": t, "base_accel_g": _adc(base, 4.0), "response_accel_g": _adc(resp, frac * peak)})
        zeta[frac] = measure_run(df, _row(12800.0))[2]["zeta_phase_resonance"]
    assert zeta[0.6] > 1.5 * zeta[2.0]  # measured: +90 % vs +13 % (the clean run's sweep-rate bias)
