"""The calibrate and posterior rules in Snakemake, on synthetic modal tables.

The test builds its own Snakefile from common.smk + calibrate.smk + posterior.smk (the
repository's config and schema), so the two stages run on synthetic modal tables
without the upstream stages.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from jointcal.models import harmonic_balance
from tests._support.campaign import unit
from tests._support.modal_tables import M, TABLE_3_2, write_tables
from tests._support.workflow import snakemake

pytestmark = pytest.mark.slow

SNAKEFILE = """\
from snakemake.utils import validate

configfile: "workflow/config/config.yaml"

validate(config, "workflow/schemas/config.schema.yaml")

include: "workflow/rules/common.smk"
include: "workflow/rules/calibrate.smk"
include: "workflow/rules/posterior.smk"
include: "workflow/rules/summary.smk"

rule all:
    default_target: True
    input:
        rules.calibrate.input,
        rules.posterior.input,
        rules.summary.input,
"""
SMALL = ["--configfile", "small.yaml"]  # a small GA and a short chain, merged over the defaults


@pytest.fixture
def workdir(workdir: Path) -> Path:
    """The workflow copy (tests/workflow/conftest.py) with SNAKEFILE for its Snakefile, small settings, a manifest
    naming the two assemblies and the modal stage's tables of Table 3.2's joints."""
    work = workdir
    (work / "Snakefile").write_text(SNAKEFILE)
    (work / "small.yaml").write_text(yaml.safe_dump({
        "calibrate": {"population": 40, "offspring": 40, "generations": 8, "n_polish": 2},
        "posterior": {"max_steps": 600, "chunk": 300}}))
    raw = work / "raw_data"
    raw.mkdir()
    pd.DataFrame({"run_id": ["a1", "b1"], "assembly": ["first", "reassembly"], "file": ["a1.csv", "b1.csv"]}).to_csv(
        raw / "manifest.csv", index=False)
    write_tables(work / "results", TABLE_3_2, seed=3)
    return work


def test_calibrate_then_posterior_then_nothing_to_do_until_the_config_changes(workdir):
    res = snakemake(workdir, "--cores", "2", "calibrate", *SMALL)
    assert res.returncode == 0, res.stderr
    out = workdir / "results"
    for a in TABLE_3_2:
        assert (out / "calibration" / a / unit(out, a) / "ga_best.json").is_file()
        assert (out / "figures" / f"ga_exploration_{a}_{unit(out, a)}.png").stat().st_size > 10_000
        assert "calibrated" in (out / "logs" / "calibrate" / a / f"{unit(out, a)}.log").read_text()
    assert not (out / "posterior").exists()  # `calibrate` runs only what it needs
    res = snakemake(workdir, "--cores", "2", "posterior", "summary", *SMALL)
    assert res.returncode == 0, res.stderr
    assert "calibrate_assembly" not in res.stderr  # the GA is not rerun
    for a in TABLE_3_2:
        assert "NOT converged" in (out / "posterior" / a / unit(out, a) / "constraints.txt").read_text()  # 600 steps only
        assert (out / "figures" / f"corner_{a}_{unit(out, a)}.png").is_file()
    table = pd.read_csv(out / "posterior" / "table_3_2.csv")
    assert len(table) == 12 and set(table["assembly"]) == set(TABLE_3_2)
    md = (out / "posterior" / "table_3_2.md").read_text()
    assert "| first | GA optimum (one member of the posterior's set) |" in md and "not identified (spans" in md
    qvh = pd.read_csv(out / "posterior" / "qsma_vs_harmonic_balance.csv")
    assert (qvh["df_percent"] > 0).all()  # QSMA sits above harmonic balance
    res = snakemake(workdir, "--cores", "2", "-n", "posterior", "summary", *SMALL)
    assert res.returncode == 0 and "Nothing to be done" in res.stdout + res.stderr
    small = yaml.safe_load((workdir / "small.yaml").read_text())
    small["calibrate"]["eta"] = 0.9
    (workdir / "small.yaml").write_text(yaml.safe_dump(small))
    res = snakemake(workdir, "--cores", "2", "-n", "posterior", *SMALL)  # a config edit reruns the GA and what follows
    assert res.returncode == 0 and "calibrate_assembly" in res.stdout + res.stderr
    res = snakemake(workdir, "--cores", "2", "--report", str(workdir / "report.html"), *SMALL)
    assert res.returncode == 0, res.stderr
    html = (workdir / "report.html").read_text()
    assert (workdir / "report.html").stat().st_size > 100_000
    # the report opens on a summary (workflow.rst with the convergence lines) and renders Table 3.2 in HTML
    assert "Open" in html and "0. Summary" in html and "NOT converged" in html
    summary = (out / "report" / "summary.html").read_text()
    assert "NOT converged" in summary and "<table class='t32'>" in summary and "polished optimum" in summary
    assert summary.count("GA best before polish") == 2 and "first" in (out / "report" / "landing.html").read_text()
    # without the validation, discrepancy and design stages the verdict says they did not run, in its order
    assert summary.index("The validation stage did not run") < summary.index("What do the data identify")
    assert "The design stage did not run" in summary
    assert "This run: NOT converged" in (out / "report" / f"corner_first_{unit(out, 'first')}.rst").read_text()


def test_the_unit_rules_pass_a_ring_downs_windows_from_backbone_csv_to_calibrate_and_posterior(workdir):
    """A ring-down run added to assembly first: modal_unit writes the unit's backbone.csv with its windows, the GA
    reads its 20 windows as one read-out beside the twelve sweeps, and so does the posterior."""
    out = workdir / "results"
    modal = pd.read_csv(out / "modal" / "modal_properties.csv", dtype={"flags": str})
    backbone = pd.read_csv(out / "modal" / "backbone.csv", dtype={"run_id": str, "mode": str})
    mode = backbone.loc[backbone["run_id"].str.startswith("first"), "mode"].iloc[0]
    t = TABLE_3_2["first"]
    q = np.geomspace(1e-4, 3e-6, 20)
    f, z = harmonic_balance(q, t["Fs"], t["KT"], t["chi"], t["beta"], t["k"], M, t["zeta_v"])
    row = dict(run_id="first_rd", assembly="first", sequence=13, level_g=10.0, direction="", test="ringdown",
               f_res_method="ringdown", q_in=q[0], f_res_hz=f[0], zeta_res=z[0], zeta_phase_resonance=z[0],
               zeta_half_power=z[0], flags="")
    pd.concat([modal, pd.DataFrame([row])], ignore_index=True).to_csv(out / "modal" / "modal_properties.csv",
                                                                       index=False)
    windows = pd.DataFrame({"run_id": "first_rd", "mode": mode, "test": "ringdown", "q_in": q, "f_hz": f, "zeta": z})
    pd.concat([backbone, windows], ignore_index=True).to_csv(out / "modal" / "backbone.csv", index=False)
    target = f"results/posterior/first/{mode}/summary.csv"
    res = snakemake(workdir, "--cores", "2", target, *SMALL)
    assert res.returncode == 0, res.stderr
    unit_bb = pd.read_csv(out / "modal" / "first" / mode / "backbone.csv")
    assert (unit_bb["run_id"] == "first_rd").sum() == 20 and len(unit_bb) == 12 + 20
    assert not unit_bb["run_id"].str.startswith("reassembly").any()
    best = json.loads((out / "calibration" / "first" / mode / "ga_best.json").read_text())
    assert (best["n_runs"], best["n_points"], best["n_readouts"]) == (13, 32, 13.0)
    assert "(32 points, 13 read-outs)" in (out / "logs" / "calibrate" / "first" / f"{mode}.log").read_text()
    assert "weight 1/20 each" in (out / "logs" / "posterior" / "first" / f"{mode}.log").read_text()


def test_bad_input_is_one_sentence_naming_the_file(workdir):
    modal = workdir / "results" / "modal" / "modal_properties.csv"
    df = pd.read_csv(modal, dtype={"flags": str})
    df.loc[df["assembly"] == "first", "flags"] = "unusable"
    df.to_csv(modal, index=False)
    mode = unit(workdir / "results", "first")
    # that GA alone: not the other's too
    res = snakemake(workdir, "--cores", "2", f"results/calibration/first/{mode}/ga_best.json", *SMALL)
    assert res.returncode != 0
    assert (f"results/modal/first/{mode}/modal_properties.csv: all 12 runs of assembly 'first' are flagged unusable"
            in res.stderr), res.stderr
    assert "Traceback" not in (workdir / "results" / "logs" / "calibrate" / "first" / f"{mode}.log").read_text()
