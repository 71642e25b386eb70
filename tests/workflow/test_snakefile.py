"""Run the Snakemake workflow on the small campaign from a copy of the repository's workflow."""
from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from tests._support.campaign import REPO, edit_run, unit
from tests._support.workflow import snakemake, workflow_copy

pytestmark = pytest.mark.slow


# light settings: these tests check the wiring and the reruns; tests/calibrate, posterior, validate and
# discrepancy check the methods
SMALL = {"calibrate": {"population": 20, "offspring": 20, "generations": 3, "n_polish": 0},
         "posterior": {"max_steps": 100, "chunk": 100, "predictive_draws": 10}, "validate": {"n_draws": 2}}


@pytest.fixture(scope="module")
def small_run(tmp_path_factory, small_campaign) -> tuple[Path, Path, subprocess.CompletedProcess[str]]:
    """One workflow copy and one run on the small campaign, shared by the tests below: a bare `snakemake
    validate` (no --cores: the default profile) with light settings (small.yaml). Each test that edits
    small.yaml puts it back."""
    tmp = tmp_path_factory.mktemp("small_run")
    work = workflow_copy(tmp)
    (work / "small.yaml").write_text(yaml.safe_dump(SMALL))
    out = tmp / "results"
    res = snakemake(work, "validate", "--configfile", "small.yaml", "--config", f"raw_data={small_campaign}",
                    f"results={out}")
    return work, out, res


def _again(small_run, small_campaign, *args: str) -> subprocess.CompletedProcess[str]:
    work, out, _ = small_run
    return snakemake(work, "--cores", "2", *args, "--configfile", "small.yaml", "--config",
                     f"raw_data={small_campaign}", f"results={out}")


def test_ingest_rule_tabulates_every_run(small_run, small_campaign):
    _, out, res = small_run
    assert res.returncode == 0, res.stderr
    runs = pd.read_csv(out / "ingest" / "runs.csv")
    manifest = pd.read_csv(small_campaign / "manifest.csv")
    assert list(runs["run_id"]) == list(manifest["run_id"])
    assert "ingested 5 runs" in (out / "logs" / "ingest.log").read_text()


def test_bare_run_uses_default_profile(small_run):
    _, out, res = small_run
    assert res.returncode == 0, res.stderr
    assert "profiles/default" in res.stderr + res.stdout
    assert (out / "ingest" / "runs.csv").is_file()


def test_validate_stage_reruns_only_itself_on_a_config_edit(small_run, small_campaign):
    """`snakemake validate` on the small campaign; then -n: nothing; an edit of validate: only it."""
    work, out, res = small_run
    assert res.returncode == 0, res.stderr
    summary = json.loads((out / "validation" / "first" / unit(out, "first") / "summary.json").read_text())
    assert np.isfinite(summary["E"]) and "peak response" in summary["words"]
    metrics = pd.read_csv(out / "validation" / "first" / unit(out, "first") / "metrics.csv")
    assert len(metrics) == 5 and (metrics["n_frames"] > 0).all()
    assert (out / "figures" / "fig3_11_validation.png").stat().st_size > 10_000
    assert "validation envelope error E" in (out / "logs" / "validate" / "first" / f"{unit(out, 'first')}.log").read_text()
    assert "Nothing to be done" in _again(small_run, small_campaign, "-n", "validate").stdout
    edited = {**SMALL, "validate": {"n_draws": 3}}
    (work / "small.yaml").write_text(yaml.safe_dump(edited))
    try:
        dry = _again(small_run, small_campaign, "-n", "validate").stdout
    finally:
        (work / "small.yaml").write_text(yaml.safe_dump(SMALL))
    assert "validate_assembly" in dry and "calibrate_assembly" not in dry and "posterior_assembly" not in dry


def test_discrepancy_target_runs_that_stage_alone_on_top(small_run, small_campaign):
    """`snakemake discrepancy` (light settings) after the validation runs that stage alone and writes its outputs."""
    work, out, res = small_run
    assert res.returncode == 0, res.stderr
    light = {**SMALL, "discrepancy": {"candidates": ["sensor_gain", "channel_delay"], "max_nfev": 8,
                                      "max_frames": 24, "ga_generations": 2, "posterior_steps": 100}}
    (work / "small.yaml").write_text(yaml.safe_dump(light))
    try:
        res = _again(small_run, small_campaign, "discrepancy")
    finally:
        (work / "small.yaml").write_text(yaml.safe_dump(SMALL))
    assert res.returncode == 0, res.stderr
    ran = set(re.findall(r"rule (\w+):", res.stdout + res.stderr))
    assert ran == {"discrepancy_assembly", "discrepancy_table", "discrepancy"}, ran
    d = json.loads((out / "discrepancy" / "first" / unit(out, "first") / "diagnosis.json").read_text())
    assert d["effect"] in {"sensor_gain", "channel_delay", "none", "unexplained"}
    assert np.isfinite(d["metric_before"]) and np.isfinite(d["metric_after"]) and "emcee" in d["recalibrated"]["method"]
    assert (out / "discrepancy" / "first" / unit(out, "first") / "diagnosis.md").read_text().startswith("# Discrepancy diagnosis")
    assert "<table>" in (out / "discrepancy" / "table_3_2_corrected.html").read_text()


def test_malformed_campaign_fails_naming_the_file(workdir, tmp_path, campaign):
    edit_run(campaign, "run03.csv.gz", lambda d: d.rename(columns={"response_accel_g": "resp_g"}))
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "ingest", "--config", f"raw_data={campaign}", f"results={out}")
    assert res.returncode != 0
    assert "run03.csv.gz: column 'response_accel_g' is missing" in res.stderr
    assert "run03.csv.gz" in (out / "logs" / "ingest.log").read_text()
    assert not (out / "ingest" / "runs.csv").exists()


def test_missing_manifest_is_one_clear_line(workdir, tmp_path):
    res = snakemake(workdir, "-n", "--cores", "2", "--config", f"raw_data={tmp_path / 'nowhere'}")
    assert res.returncode != 0
    assert "nowhere/manifest.csv: the campaign manifest does not exist" in res.stderr
    assert "Traceback" not in res.stderr and "File " not in res.stderr


def test_lint_reports_only_the_expected_conda_advice(workdir, small_campaign, tmp_path):
    """`snakemake --lint` of the whole workflow: every rule file (the calibrate, posterior and summary rules that
    test_calibration.py runs on their own among them) draws only the conda advice."""
    res = snakemake(workdir, "--lint", "--config", f"raw_data={small_campaign}", f"results={tmp_path / 'r'}")
    items = [line.strip() for line in (res.stdout + res.stderr).splitlines() if line.strip().startswith("* ")]
    assert items, res.stdout + res.stderr  # snakemake --lint always asks for conda (STYLE.md trap 4)
    assert set(items) == {"* Specify a conda environment or container for each rule.:"}, res.stdout + res.stderr


@pytest.mark.acceptance
def test_default_config_runs_on_the_example_campaign(workdir, tmp_path):
    """`snakemake --cores 2` with the default raw_data/ (linked into the copy) runs every stage."""
    (workdir / "raw_data").symlink_to(REPO / "raw_data")
    out = tmp_path / "results"
    # a short posterior and a lighter validation/discrepancy: this test checks the wiring (and that the
    # example's hidden can flexibility is named); tests/posterior and tests/discrepancy check the methods
    (workdir / "short.yaml").write_text("posterior: {max_steps: 2000, chunk: 500}\nvalidate: {n_draws: 2}\n"
                                        "discrepancy: {candidates: [sensor_gain, channel_delay, fixture_flexibility], "
                                        "max_nfev: 15, ga_generations: 5, posterior_steps: 200}\n")
    res = snakemake(workdir, "--cores", "2", "--configfile", "short.yaml", "--config", f"results={out}")
    assert res.returncode == 0, res.stderr
    runs = pd.read_csv(out / "ingest" / "runs.csv")
    assert len(runs) == 24 and runs["flags"].isna().all()
    assert set(runs["assembly"]) == {"first", "reassembly"}
    modal = pd.read_csv(out / "modal" / "modal_properties.csv")
    assert len(modal) == 24 and modal["f_res_hz"].notna().all()
    assert (out / "figures" / "fig3_5_envelopes.png").is_file()
    for asm in ("first", "reassembly"):
        assert (out / "calibration" / asm / unit(out, asm) / "ga_best.json").is_file()
        assert (out / "posterior" / asm / unit(out, asm) / "summary.csv").is_file()
    assert (out / "posterior" / "table_3_2.md").is_file()
    assert (out / "figures" / "fig3_11_validation.png").is_file()
    for asm in ("first", "reassembly"):
        d = json.loads((out / "discrepancy" / asm / unit(out, asm) / "diagnosis.json").read_text())
        assert d["effect"] == "fixture_flexibility" and d["metric_after"] < 0.3 * d["metric_before"]
    for asm in ("first", "reassembly"):  # the design stage: a next test within the shaker limit, its predictions
        nt = json.loads((out / "design" / asm / unit(out, asm) / "next_test.json").read_text())
        assert {"level_g", "direction", "sweep_rate_hz_per_s"} <= set(nt["recommended"])
        assert nt["recommended"]["level_g"] <= 100.0 and {"Fs", "KT", "KT/k"} <= set(nt["predicted_width_ratio"])
        assert (out / "figures" / f"next_test_{asm}_{unit(out, asm)}.png").is_file() and (out / "design" / asm / unit(out, asm) / "next_test.csv").is_file()
    # the summary opens on the verdict, in its order, before Table 3.2 and the details
    page = (out / "report" / "summary.html").read_text()
    order = [page.index(s) for s in ("reproduce the measured envelopes", "fixture_flexibility",
                                     "What do the data identify", "The next test", "Table 3.2", "Details")]
    assert order == sorted(order)
