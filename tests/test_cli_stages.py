"""The stage subcommands of the command line (``jointcal modal``, ``jointcal calibrate``, ...): each runs the
function its workflow script calls, and writes what the script writes for the same inputs.

One end-to-end run on the small campaign (ingest, envelopes, modal, unit, calibrate with a small GA) through
``python -m jointcal.cli``; the modal and calibrate scripts then run on the same inputs with a stand-in for
Snakemake's ``snakemake`` object, and their outputs must equal the command line's byte for byte.
"""
from __future__ import annotations

import ast
import inspect
import runpy
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
import yaml
from tests._support.campaign import SMALL_CAMPAIGN

from jointcal import cli
from jointcal._campaign_index import campaign_index

REPO = Path(__file__).resolve().parents[1]
SCRIPTS = REPO / "workflow" / "scripts"
SMALL_GA = {"calibrate": {"population": 40, "offspring": 40, "generations": 8, "n_polish": 2}}
# workflow script -> the subcommand that runs the same stage function
SUBCOMMAND = {"envelopes.py": "envelopes", "modal.py": "modal", "modal_unit.py": "unit", "calibrate.py": "calibrate",
              "posterior.py": "posterior", "validate.py": "validate", "discrepancy.py": "discrepancy",
              "design.py": "design"}


def _cli(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "jointcal.cli", *map(str, args)], capture_output=True, text=True)


def _ok(res: subprocess.CompletedProcess[str]) -> str:
    assert res.returncode == 0, res.stderr
    assert "Traceback" not in res.stderr
    return res.stdout


def _run_script(name: str, log: Path, **parts) -> None:
    """Run workflow/scripts/`name` as Snakemake would, with `parts` (input, output, params, wildcards)."""
    smk = SimpleNamespace(threads=1, log=[str(log)], **{k: SimpleNamespace(**v) for k, v in parts.items()})
    runpy.run_path(str(SCRIPTS / name), init_globals={"snakemake": smk}, run_name="__main__")


def _same_files(a: Path, b: Path) -> list[str]:
    """The files under `a` and `b` (same relative names) whose bytes differ, or that only one holds."""
    na = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    nb = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    return sorted(str(n) for n in na ^ nb) + sorted(str(n) for n in na & nb if (a / n).read_bytes() != (b / n).read_bytes())


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory) -> dict:
    """The small campaign through the command line, ingest to calibrate; the stdout of each stage."""
    d = tmp_path_factory.mktemp("cli")
    (d / "small.yaml").write_text(yaml.safe_dump(SMALL_GA))
    runs = d / "runs.csv"
    out = {"ingest": _ok(_cli("ingest", SMALL_CAMPAIGN, runs)),
           "envelopes": _ok(_cli("envelopes", SMALL_CAMPAIGN, "--runs", runs, "--out", d / "envelopes")),
           "modal": _ok(_cli("modal", SMALL_CAMPAIGN, "--runs", runs, "--envelopes", d / "envelopes",
                             "--out", d / "modal"))}
    unit = d / "modal" / "first" / "m2200"
    out["unit"] = _ok(_cli("unit", d / "modal", "--assembly", "first", "--mode", "m2200"))
    out["calibrate"] = _ok(_cli("calibrate", "--modal", unit / "modal_properties.csv", "--backbone",
                                unit / "backbone.csv", "--assembly", "first", "--out", d / "calibration",
                                "--config", d / "small.yaml"))
    return {"dir": d, "stdout": out}


@pytest.mark.slow
def test_cli_runs_the_stages_and_prints_their_log_lines(cli_run):
    d, out = cli_run["dir"], cli_run["stdout"]
    assert out["envelopes"].count("\n") == 5 and "run01: " in out["envelopes"]
    assert out["modal"].strip().endswith("modal properties of 5 runs at 1 modes, 5 rows flagged")
    assert out["unit"].strip() == "jointcal: first m2200: 5 runs (run01, run02, run03, run04, run05)"
    assert "GA generation 8/8" in out["calibrate"] and "after 8 generations" in out["calibrate"]
    assert all(line.startswith("jointcal: ") for text in out.values() for line in text.splitlines())
    assert {p.name for p in (d / "calibration").iterdir()} == {"ga_best.json", "ga_history.csv", "ga_logbook.csv",
                                                             "model_curves.csv"}


@pytest.mark.slow
def test_modal_and_calibrate_write_what_the_workflow_scripts_write(cli_run, tmp_path):
    d = cli_run["dir"]
    records = list(campaign_index(SMALL_CAMPAIGN / "manifest.csv").run_files.values())
    env = sorted(str(p) for p in (d / "envelopes").glob("*.csv"))
    config = cli.read_config(d / "small.yaml")
    modal = tmp_path / "modal"
    _run_script("modal.py", tmp_path / "modal.log",
                input={"runs": str(d / "runs.csv"), "env": env, "records": records},
                output={"table": str(modal / "modal_properties.csv"), "scatter": str(modal / "scatter.csv"),
                        "backbone": str(modal / "backbone.csv"), "frf": str(modal / "frf")},
                params={"modal": config["modal"]})
    unit = d / "modal" / "first" / "m2200"
    cal = tmp_path / "calibration"
    _run_script("calibrate.py", tmp_path / "calibrate.log",
                input={"modal": str(unit / "modal_properties.csv"), "backbone": str(unit / "backbone.csv")},
                output={"best": str(cal / "ga_best.json")},
                params={"calibrate": config["calibrate"], "checkpoint": None},
                wildcards={"assembly": "first"})
    assert _same_files(d / "calibration", cal) == []
    cli_modal = d / "modal"
    assert not _same_files(cli_modal / "frf", modal / "frf")
    for name in ("modal_properties.csv", "scatter.csv", "backbone.csv"):
        assert (cli_modal / name).read_bytes() == (modal / name).read_bytes(), name
    log = (tmp_path / "modal.log").read_text().splitlines()
    assert log[-1] == cli_run["stdout"]["modal"].splitlines()[-1]  # the same one-line log


def test_each_stage_subcommand_calls_the_function_its_script_calls():
    """The function each workflow script imports from the package (besides stage_job) is the one its
    subcommand calls."""
    for script, command in SUBCOMMAND.items():
        tree = ast.parse((SCRIPTS / script).read_text())
        called = {a.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                  and node.module != "jointcal._stage_job" for a in node.names}
        cmd = inspect.getsource(getattr(cli, f"_cmd_{command}"))
        stage = [n for n in called if n.startswith("run_")]
        assert len(stage) == 1, (script, called)
        assert f"import {stage[0]}" in cmd or f", {stage[0]}" in cmd, (script, command)
        assert f"{stage[0]}(" in cmd


def test_a_bad_setting_or_input_is_one_sentence_and_exit_2(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("calibrate:\n  populaton: 40\n")
    res = _cli("calibrate", "--modal", tmp_path / "none.csv", "--assembly", "first", "--out", tmp_path / "cal",
               "--config", bad)
    assert res.returncode == 2 and res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert res.stderr.startswith("jointcal: ") and "'calibrate.populaton'" in res.stderr and "population" in res.stderr
    missing = _cli("calibrate", "--modal", tmp_path / "none.csv", "--assembly", "first", "--out", tmp_path / "cal")
    assert missing.returncode == 2 and missing.stderr.startswith("jointcal: ") and "none.csv" in missing.stderr
    assert not (tmp_path / "cal").exists()
