"""Tests of the command line (``python -m jointcal.cli`` and ``main``)."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd

from jointcal import __version__
from jointcal.cli import main
from tests._support.campaign import edit_run
from tests._support.ingest import _one_sentence, _set


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "jointcal.cli", *args], capture_output=True, text=True)


def test_ingest_writes_one_row_per_run(tmp_path, small_campaign):
    out = tmp_path / "sub" / "runs.csv"
    res = _cli("ingest", str(small_campaign), str(out))
    assert res.returncode == 0, res.stderr
    runs = pd.read_csv(out)
    assert list(runs["run_id"]) == ["run01", "run02", "run03", "run04", "run05"]
    assert "wrote 5 runs" in res.stdout


def test_bad_campaign_exits_2_with_one_line_and_writes_nothing(tmp_path, campaign):
    edit_run(campaign, "run03.csv.gz", lambda d: d.drop(columns="response_accel_g"))
    out = tmp_path / "runs.csv"
    res = _cli("ingest", str(campaign), str(out))
    assert res.returncode == 2
    assert res.stderr.startswith("jointcal: ") and "run03.csv.gz" in res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert not out.exists()


def test_flag_option_turns_nan_into_a_flag(tmp_path, campaign, capsys):
    def nan_at_10(d):
        d.loc[10, "response_accel_g"] = float("nan")

    edit_run(campaign, "run02.csv.gz", nan_at_10)
    out = tmp_path / "runs.csv"
    assert main(["ingest", str(campaign), str(out)]) == 2
    assert "run02.csv.gz" in capsys.readouterr().err
    assert main(["ingest", str(campaign), str(out), "--on-data-problem", "flag"]) == 0
    err = capsys.readouterr().err
    assert err.startswith("jointcal: warning: ") and "run02.csv.gz" in err and err.count("\n") == 1
    runs = pd.read_csv(out, keep_default_na=False).set_index("run_id")
    assert runs.loc["run02", "flags"] == "nonfinite:response_accel_g"


def test_version_and_usage():
    res = _cli("--version")
    assert res.returncode == 0 and res.stdout.strip() == f"jointcal {__version__}"
    assert _cli().returncode == 2


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
