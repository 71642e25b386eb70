"""How the workflow behaves around the science: reruns that follow the code, config messages,
progress in the logs, no stale outputs after a failure, and the slurm profile.

The Snakemake tests run on a copy of the repository's Snakefile, workflow/ and src/jointcal
(so a module can be edited) with the small committed campaign, and mark the workflow's
outputs as made with ``--touch`` instead of computing them: what is checked is which jobs
Snakemake schedules, not what they compute (test_workflow.py runs them for real).
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pandas as pd
import pytest
from tests._support.campaign import REPO, SMALL_CAMPAIGN, edit_manifest
from tests._support.modal_tables import TABLE_3_2, modal_tables, write_tables
from tests._support.workflow import snakemake, workflow_copy

from jointcal import _workflow
from jointcal._workflow import campaign_index, config_problem, pending_outputs, stage_sources
from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.posterior import PosteriorSettings, run_posterior

SCRIPTS = REPO / "workflow" / "scripts"
SCHEMA = REPO / "workflow" / "schemas" / "config.schema.yaml"
PER_UNIT = {"modal_unit", "calibrate_assembly", "calibration_figures", "posterior_assembly", "posterior_corner",
            "validate_assembly", "discrepancy_assembly", "design_assembly"}
DOWNSTREAM_OF_MODAL = {"modal_properties", "modal_figures", "modal_unit", "calibrate_assembly", "calibration_figures",
                       "posterior_assembly", "posterior_corner", "posterior_report", "report_summary",
                       "validate_assembly", "validate_figures", "discrepancy_assembly", "discrepancy_table",
                       "design_assembly"}


def _names(files: list[Path]) -> set[str]:
    return {f.relative_to(REPO / "src" / "jointcal").as_posix() for f in files[1:]}


def test_stage_sources_follow_imports_through_the_package():
    assert stage_sources(SCRIPTS / "modal.py")[0] == SCRIPTS / "modal.py"  # the script's own text counts too
    modal = _names(stage_sources(SCRIPTS / "modal.py"))
    assert {"measure/modal.py", "measure/envelopes.py", "io/__init__.py", "io/_checks.py", "__init__.py"} <= modal
    assert not any(n.startswith(("calibrate/", "posterior/", "report/")) for n in modal)
    assert "measure/modal.py" not in _names(stage_sources(SCRIPTS / "ingest.py"))
    assert "measure/modal.py" not in _names(stage_sources(SCRIPTS / "envelopes.py"))
    # `from ..calibrate.space import ...` in report/calibration.py, and the packages' __init__ files
    figures = _names(stage_sources(SCRIPTS / "calibration_figures.py"))
    assert {"report/__init__.py", "report/calibration.py", "calibrate/__init__.py", "calibrate/space.py"} <= figures


def test_an_edit_of_measure_peaks_changes_no_stage_hash_before_modal(tmp_path, monkeypatch):
    """The hash the rules pass as params (common.smk's source_hash: `stage_hash` of the script), on a copy of the
    package whose measure/peaks.py is edited: ingest, envelopes and the kernels keep theirs, modal's changes."""
    before_modal = [re.search(r'script:\s*"\.\./scripts/(\w+\.py)"', block).group(1)
                    for smk in ("ingest", "envelopes", "kernels")
                    for block in re.split(r"(?m)^(?=rule )", (REPO / "workflow" / "rules" / f"{smk}.smk").read_text())
                    if "script:" in block]
    assert {"ingest.py", "envelopes.py", "kernels.py"} <= set(before_modal)
    pkg = tmp_path / "jointcal"
    shutil.copytree(REPO / "src" / "jointcal", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(_workflow, "_ROOT", pkg.resolve())
    hashes = {s: _workflow.stage_hash(SCRIPTS / s) for s in [*before_modal, "modal.py"]}
    _edit(pkg / "measure" / "peaks.py")
    assert {s: _workflow.stage_hash(SCRIPTS / s) for s in before_modal} == {s: hashes[s] for s in before_modal}
    assert _workflow.stage_hash(SCRIPTS / "modal.py") != hashes["modal.py"]  # the hash does see the edit


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


def test_typo_in_a_nested_key_names_the_nearest_valid_key():
    config = {"raw_data": "raw_data", "calibrate": {"bounds": {"Fs": [1, 10]}, "populaton": 40}}
    msg = config_problem(config, SCHEMA)
    assert msg is not None and "\n" not in msg
    assert "'calibrate.populaton'" in msg and "did you mean 'calibrate.population'?" in msg
    assert "did you mean 'resul" in config_problem({"resuls": "out"}, SCHEMA)


def test_nested_config_given_as_text_is_converted_or_named_in_one_line():
    config = {"posterior": {"ball": "0.005", "rel_std_floor": {"frequency": "1e-3"}},  # as --config leaves them
              "calibrate": {"bounds": {"Fs": ["1", "100"]}, "model": "qsma"}}
    assert config_problem(config, SCHEMA) is None
    assert config["posterior"]["ball"] == 0.005 and config["posterior"]["rel_std_floor"]["frequency"] == 1e-3
    assert config["calibrate"]["bounds"]["Fs"] == [1, 100] and config["calibrate"]["model"] == "qsma"
    msg = config_problem({"posterior": {"ball": "small"}}, SCHEMA)
    assert msg.startswith("config 'posterior.ball': 'small' is not of type 'number'")
    assert "--configfile my.yaml" in msg and "\n" not in msg


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


def test_campaign_index_reads_the_manifest_and_keeps_its_problem(campaign):
    manifest = pd.read_csv(SMALL_CAMPAIGN / "manifest.csv", dtype=str)
    index = campaign_index(SMALL_CAMPAIGN / "manifest.csv")
    assert list(index.run_files) == list(manifest["run_id"]) and index.problem is None
    assert index.run_files[manifest["run_id"][0]] == str(SMALL_CAMPAIGN / manifest["file"][0])
    assert index.assemblies == list(dict.fromkeys(manifest["assembly"])) and index.excitation == "base"
    first = manifest["assembly"][0]
    assert index.assembly_files(first) == [str(SMALL_CAMPAIGN / f) for f in manifest.loc[manifest["assembly"] == first,
                                                                                         "file"]]
    # a listed record that is missing: the names still come through, with read_manifest's sentence kept
    edit_manifest(campaign, lambda d: d.assign(file=d["file"].where(d.index > 0, "gone.csv")))
    broken = campaign_index(campaign / "manifest.csv")
    assert list(broken.run_files) == list(manifest["run_id"]) and broken.excitation == "base"
    assert "gone.csv: the file of run" in broken.problem
    edit_manifest(campaign, lambda d: d.rename(columns={"level_g": "level_V"}))  # the records are not read
    assert campaign_index(campaign / "manifest.csv").excitation == "voltage"


def test_pending_outputs_are_the_planned_files_written_before_the_run(tmp_path):
    old, new, done = tmp_path / "old.csv", tmp_path / "new.csv", tmp_path / "done.csv"
    for f in (old, done, new):
        f.write_text("x\n")
    os.utime(old, (1000.0, 1000.0))
    os.utime(done, (1000.0, 1000.0))
    summary = ("output_file\tdate\trule\tlog-file(s)\tstatus\tplan\n"
               f"{old}\t-\tr\t-\tok\tupdate pending\n{done}\t-\tr\t-\tok\tno update\n"
               f"{new}\t-\tr\t-\tok\tupdate pending\n{tmp_path / 'missing.csv'}\t-\tr\t-\tmissing\tupdate pending\n"
               f"{tmp_path}\t-\tr\t-\tok\tupdate pending\n")
    assert pending_outputs(summary, before=2000.0) == [old]  # not new (written since), done, missing, a folder
    assert pending_outputs("Building DAG of jobs...", before=2000.0) == []


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


def _edit(path: Path) -> str:
    """Append a comment to a module (a change to its text, not to what it does); return the original."""
    text = path.read_text()
    path.write_text(text + "\n# edited by test_workflow_mechanics\n")
    return text


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
    work = tmp_path / "wf"
    work.mkdir()
    shutil.copy(REPO / "Snakefile", work)
    shutil.copytree(REPO / "workflow", work / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(REPO / "src" / "jointcal", work / "src" / "jointcal", ignore=shutil.ignore_patterns("__pycache__"))
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


def _settings(node, path=()):
    """Every leaf setting of a config (path, value), a list being one setting."""
    if isinstance(node, dict) and node:
        for k, v in node.items():
            yield from _settings(v, (*path, k))
    else:
        yield path, node


def test_every_setting_given_on_the_command_line_as_the_readme_shows_is_read_as_its_value():
    """Each setting of config.yaml given as ``--config 'section={key: value}'`` (Snakemake's own parser,
    which leaves nested values as text) is read back as the value the config file gives, or stops in one
    sentence; a list-or-null setting (modal.mode_hz) takes a number, a list and null."""
    import yaml
    from snakemake.cli import parse_config
    from snakemake.utils import update_config

    defaults = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    cases = [(p, v) for p, v in _settings(defaults)]
    cases += [(("modal", "mode_hz"), 95.0), (("modal", "mode_hz"), [18.6, 95.0]), (("modal", "mode_hz"), None)]
    assert len(cases) > 40  # the walk reached the nested sections
    for path, value in cases:
        text = yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()
        for key in reversed(path[1:]):
            text = f"{{{key}: {text}}}"
        config = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
        update_config(config, parse_config([f"{path[0]}={text}"]))
        assert config_problem(config, SCHEMA) is None, (path, text)
        got = config
        for key in path:
            got = got[key]
        assert got == value, (path, text, got)
    msg = config_problem({"modal": {"mode_hz": ["95", "high"]}}, SCHEMA)
    assert msg is not None and "\n" not in msg and "modal.mode_hz" in msg
