"""How the workflow behaves around the science: reruns that follow the code, config messages,
progress in the logs, no stale outputs after a failure, and the slurm profile.

The Snakemake tests run on a copy of the repository's Snakefile, workflow/ and src/jointcal
(so a module can be edited) with the small committed campaign, and mark the workflow's
outputs as made with ``--touch`` instead of computing them: what is checked is which jobs
Snakemake schedules, not what they compute (test_snakefile.py runs them for real).
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.posterior import PosteriorSettings, run_posterior
from tests._support.campaign import REPO, SMALL_CAMPAIGN
from tests._support.modal_tables import TABLE_3_2, modal_tables, write_tables
from tests._support.workflow import _edit, snakemake, workflow_copy

PER_UNIT = {"modal_unit", "calibrate_assembly", "calibration_figures", "posterior_assembly", "posterior_corner",
            "validate_assembly", "discrepancy_assembly", "design_assembly"}
DOWNSTREAM_OF_MODAL = {"modal_properties", "modal_figures", "modal_unit", "calibrate_assembly", "calibration_figures",
                       "posterior_assembly", "posterior_corner", "posterior_report", "report_summary",
                       "validate_assembly", "validate_figures", "discrepancy_assembly", "discrepancy_table",
                       "design_assembly"}


def test_every_script_rule_carries_its_code_hash_a_benchmark_and_slurm_threads():
    """A stage added later gets the same treatment (checked on the rule files' text)."""
    import yaml

    profile = yaml.safe_load((REPO / "workflow" / "profiles" / "slurm" / "config.yaml").read_text())
    rules = {}
    for smk in sorted((REPO / "workflow" / "rules").glob("*.smk")):
        for block in re.split(r"(?m)^(?=rule )", smk.read_text())[1:]:
            rules[block.split(":")[0].removeprefix("rule ")] = block
    scripted = {name: b for name, b in rules.items() if "script:" in b}
    assert len(scripted) >= 9
    for name, block in scripted.items():
        script = re.search(r'script:\s*"\.\./scripts/(\w+\.py)"', block).group(1)
        assert f'code=source_hash("{script}")' in block, name
        assert "benchmark:" in block and "__version__" not in block, name
        assert name in profile["set-threads"], name


def test_ga_generation_and_chain_tau_reach_the_log_while_running(tmp_path):
    modal_csv, scatter_csv = write_tables(tmp_path, {"a": TABLE_3_2["first"]}, seed=3)
    lines: list[str] = []
    cal = CalibrateSettings.from_config({"population": 20, "offspring": 20, "generations": 4, "checkpoint_every": 2,
                                         "stall_generations": 10, "n_polish": 0})
    run_calibration(modal_csv, "a", tmp_path / "cal", cal, progress=lines.append)
    assert [ln.split(":")[0] for ln in lines] == ["GA generation 2/4", "GA generation 4/4"]
    assert "best objective" in lines[0]
    lines.clear()
    post = PosteriorSettings.from_config({"n_walkers": 16, "max_steps": 200, "chunk": 100})
    run_posterior(modal_csv, scatter_csv, tmp_path / "cal" / "ga_best.json", "a", tmp_path / "post", cal, post,
                  checkpoint=tmp_path / "chain.npz", progress=lines.append)
    assert [ln.split(":")[0] for ln in lines] == ["posterior step 100/200", "posterior step 200/200"]
    assert re.search(r"largest autocorrelation time \d+ steps, chain [\d.]+ tau \(stops at 50 tau\); checkpoint ",
                     lines[-1]), lines[-1]


# ------------------------------------------------------------------ Snakemake runs (slow)

def _jobs(res: subprocess.CompletedProcess[str]) -> dict[str, int]:
    """Rule -> job count from a dry run's "Job stats" table (empty when nothing is to be done)."""
    out = res.stdout + res.stderr
    assert res.returncode == 0, out
    m = re.search(r"Job stats:\njob\s+count\n-+\s+-+\n(.*?)\ntotal", out, re.S)
    return {} if m is None else {k: int(v) for k, v in (ln.split() for ln in m.group(1).splitlines())}


@pytest.fixture(scope="module")
def touched(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """A copy of the workflow and package whose outputs are all marked made (``--touch -F``).

    Shared by the tests below (made once: about 8 s); each leaves it as it found it, except
    the failure test, which comes last.
    """
    work = workflow_copy(tmp_path_factory.mktemp("touched"), src=True)
    cfg = ["--config", f"raw_data={SMALL_CAMPAIGN}", f"results={work / 'results'}"]
    modal = work / "results" / "modal" / "modal_properties.csv"
    for _ in range(2):  # up to the modal checkpoint, then (once it is made) the (assembly, mode) jobs its table names
        summary = snakemake(work, "--summary", *cfg)
        assert summary.returncode == 0, summary.stderr
        for line in summary.stdout.splitlines()[1:]:
            out = Path(line.split("\t")[0])
            if not out.suffix:  # a directory() output (modal/frf, validation/<assembly>/envelopes)
                out.mkdir(parents=True, exist_ok=True)
                continue
            out.parent.mkdir(parents=True, exist_ok=True)
            out.touch()
        if not modal.stat().st_size:  # the checkpoint's table, made by an ideal modal stage
            table = modal_tables({"first": TABLE_3_2["first"]}, levels=(1, 1, 2, 5, 10))[0]
            table.assign(run_id=[f"run{i:02d}" for i in range(1, 6)], mode="m2188").to_csv(modal, index=False)
        res = snakemake(work, "--cores", "1", "--touch", "--forceall", *cfg)
        assert res.returncode == 0, res.stderr
    return work, cfg


@pytest.mark.slow
def test_editing_a_stage_module_reruns_that_stage_and_its_descendants_only(touched):
    work, cfg = touched
    pkg = work / "src" / "jointcal"
    cases = [
        # not ingest, not envelopes; the jobs of each (assembly, mode) are named once the modal checkpoint has run
        ("measure/modal.py", DOWNSTREAM_OF_MODAL - PER_UNIT),
        ("report/calibration.py", {"calibration_figures", "posterior_corner", "posterior_report", "report_summary",
                                    "validate_figures", "design_assembly"}),  # figures and report pages only
        ("design/narrowing.py", {"design_assembly", "report_summary"}),  # the design and the verdict that reads it
    ]
    for module, expected in cases:
        original = _edit(pkg / module)
        jobs = _jobs(snakemake(work, "-n", *cfg))
        assert set(jobs) - {"all"} == expected, module
        (pkg / module).write_text(original)
    assert _jobs(snakemake(work, "-n", *cfg)) == {}  # the hash is of the content: undoing an edit undoes the rerun


@pytest.mark.slow
def test_discrepancy_target_runs_only_that_stage_and_what_it_needs(touched, tmp_path):
    """`snakemake --cores 2 discrepancy` after an edit of the discrepancy code reruns that
    stage alone; from an empty results folder it runs the stages it reads and none of the figure or
    report jobs of the others."""
    work, cfg = touched
    module = work / "src" / "jointcal" / "discrepancy" / "select.py"
    original = _edit(module)
    try:
        assert set(_jobs(snakemake(work, "-n", "discrepancy", *cfg))) == {
            "discrepancy_assembly", "discrepancy_table", "discrepancy"}
    finally:
        module.write_text(original)
    fresh = ["--config", f"raw_data={SMALL_CAMPAIGN}", f"results={tmp_path / 'fresh'}"]
    jobs = set(_jobs(snakemake(work, "-n", "discrepancy", *fresh)))
    # (the jobs of each (assembly, mode), calibrate to discrepancy, are named once the modal checkpoint has run)
    assert {"ingest", "envelopes_runs", "modal_properties", "discrepancy_table"} <= jobs
    assert not jobs & {"modal_figures", "calibration_figures", "posterior_corner", "validate_figures",
                       "report_summary"}, jobs


@pytest.mark.slow
def test_typo_in_config_is_one_line_before_any_schema_dump(touched):
    work, cfg = touched
    res = snakemake(work, "-n", *cfg, "calibrate={populaton: 40}")
    assert res.returncode != 0
    assert res.stderr.strip().splitlines()[-1] == (
        "jointcal: config key 'calibrate.populaton' is not a setting of this workflow; did you mean "
        "'calibrate.population'? (all settings: workflow/config/config.yaml)")
    assert "Failed validating" not in res.stderr and "Traceback" not in res.stderr
    assert _jobs(snakemake(work, "-n", *cfg, "posterior={ball: 0.002}")) == {
        "posterior_assembly": 1, "posterior_corner": 1, "posterior_report": 1, "report_summary": 1,
        "validate_assembly": 1, "validate_figures": 1, "discrepancy_assembly": 1, "discrepancy_table": 1,
        "design_assembly": 1, "all": 1}  # params changed: the posterior and what uses its chain


@pytest.mark.slow
def test_slurm_profile_dry_run_has_one_job_per_assembly_and_mode(tmp_path, touched):
    """On the example campaign (24 runs, 2 assemblies) up to the modal checkpoint, whose table names the
    (assembly, mode) jobs after it; their resources on the touched small campaign, with the profile's values."""
    work = workflow_copy(tmp_path, src=True)
    slurm = ["--workflow-profile", "workflow/profiles/slurm"]
    res = snakemake(work, "-n", *slurm, "--config", f"raw_data={REPO / 'raw_data'}", f"results={tmp_path / 'results'}")
    assert "workflow/profiles/slurm" in res.stderr + res.stdout
    assert "checkpoint" in res.stderr + res.stdout  # the jobs after modal are named by its table
    assert _jobs(res) == {"compile_kernels": 1, "ingest": 1, "envelopes_runs": 1, "modal_properties": 1, "modal_figures": 1,
                          "posterior_report": 1, "report_summary": 1, "validate_figures": 1, "discrepancy_table": 1,
                          "all": 1}
    blocks = re.findall(r"rule (\w+):\n(?:    .*\n)*?    resources: (.*)", res.stdout + res.stderr)
    resources = {rule: dict(kv.split("=", 1) for kv in line.split(", ")) for rule, line in blocks}
    assert resources["envelopes_runs"]["runtime"] == "15" and resources["ingest"]["cpus_per_task"] == "1"
    assert resources["envelopes_runs"]["cpus_per_task"] == "2"
    twork, cfg = touched
    per_unit = ["calibrate_assembly", "posterior_assembly", "validate_assembly", "discrepancy_assembly", "design_assembly"]
    res = snakemake(twork, "-n", *slurm, *cfg, "--forcerun", *per_unit)
    jobs = _jobs(res)
    assert all(jobs[r] == 1 for r in per_unit), jobs  # the small campaign: one assembly, one mode
    assert re.search(r"wildcards: assembly=first, mode=m2188", res.stdout + res.stderr)
    blocks = re.findall(r"rule (\w+):\n(?:    .*\n)*?    resources: (.*)", res.stdout + res.stderr)
    resources = {rule: dict(kv.split("=", 1) for kv in line.split(", ")) for rule, line in blocks}
    assert resources["calibrate_assembly"]["runtime"] == "30" and resources["posterior_assembly"]["runtime"] == "60"
    assert resources["validate_assembly"]["cpus_per_task"] == "2"


@pytest.mark.slow
def test_failed_rerun_removes_the_downstream_outputs_it_could_not_remake(touched):
    work, cfg = touched
    results = work / "results"
    upstream = sorted(p for p in (results / "envelopes").iterdir()) + [results / "ingest" / "runs.csv"]
    downstream = [results / "calibration" / "first" / "m2188" / "ga_best.json",
                  results / "posterior" / "first" / "m2188" / "summary.csv",
                  results / "posterior" / "table_3_2.csv", results / "figures" / "fig3_8_amplitude_fit.png",
                  results / "figures" / "fig3_5_envelopes.png"]
    assert all(p.is_file() for p in upstream + downstream)
    modal = work / "src" / "jointcal" / "measure" / "modal.py"
    modal.write_text(modal.read_text() + "\nraise RuntimeError('a bug in the new modal code')\n")
    res = snakemake(work, "--cores", "1", *cfg)
    assert res.returncode != 0
    assert "a bug in the new modal code" in res.stderr
    assert "so nothing out of date looks current" in res.stderr
    assert not any(p.exists() for p in downstream), [p for p in downstream if p.exists()]
    assert not (results / "modal" / "modal_properties.csv").exists()  # the failed job's own (Snakemake's doing)
    assert all(p.is_file() for p in upstream)  # up to date: kept
    assert (results / "logs" / "modal.log").is_file()
