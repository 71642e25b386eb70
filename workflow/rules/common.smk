# Shared paths and input functions of the jointcal workflow (logic lives in src/jointcal/).
import csv
import os
import sys
import warnings
from pathlib import Path

from snakemake.utils import validate

from jointcal._workflow import config_problem, stage_hash
from jointcal.io import CampaignError, CampaignWarning, excitation_kind, read_manifest, write_bytes_atomic

# Config: an unknown key (a typo) is one line naming the nearest valid key, before the schema's own
# validation (whose message is a dump of the schema); nested --config values given as text are converted.
SCHEMA = Path(workflow.current_basedir).parent / "schemas" / "config.schema.yaml"
if problem := config_problem(config, SCHEMA):
    sys.exit(f"jointcal: {problem}")
validate(config, SCHEMA)

SCRIPTS = Path(workflow.current_basedir).parent / "scripts"


def source_hash(script):
    """Content hash of a stage script and every jointcal module it imports (jointcal._workflow.stage_hash).

    Passed as a rule's params, so a change to the code a stage runs reruns that stage and its
    descendants (Snakemake's params trigger); a package version nobody bumps would not.
    """
    return stage_hash(SCRIPTS / script)


RAW_DATA = Path(config["raw_data"])
RESULTS = Path(config["results"])
MANIFEST = RAW_DATA / "manifest.csv"
if not MANIFEST.is_file():
    sys.exit(
        f"jointcal: {MANIFEST}: the campaign manifest does not exist; put the campaign "
        "(manifest.csv and run files, see raw_data/README.md) there or point to it "
        "with --config raw_data=PATH/TO/CAMPAIGN."
    )


def _manifest_rows():
    """The manifest's rows as text, read leniently at parse time (a workflow of the later stages only,
    started from their tables, may hold a manifest of run_id, assembly and file alone)."""
    with open(MANIFEST, newline="", encoding="utf-8-sig") as fh:
        return [{(k or "").strip(): (v or "").strip() for k, v in r.items()} for r in csv.DictReader(fh)]


RUN_FILES = {r["run_id"]: str(RAW_DATA / r.get("file", "")) for r in _manifest_rows() if r.get("run_id")}
RUN_IDS = list(RUN_FILES)
ASSEMBLIES = list(dict.fromkeys(r["assembly"] for r in _manifest_rows() if r.get("assembly")))
# the campaign's reference kind from the manifest's level column (base unless level_lbf / level_V)
EXCITATION = excitation_kind(_manifest_rows()[0]) if _manifest_rows() else "base"
_CHECKED = []


def checked_campaign():
    """Read and check the manifest once, with jointcal.io.read_manifest, in the input function of every rule
    that reads raw records: a Windows path, a listed file that is missing or any other manifest problem
    stops the workflow there with the one-sentence message on stderr and in the ingest log, before
    Snakemake looks for the records (its MissingInputException names no fix). Notes on the manifest
    (empty trailing rows) are left to the ingest stage's log."""
    if not _CHECKED:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", CampaignWarning)
                _CHECKED.append(read_manifest(MANIFEST))
        except CampaignError as exc:
            write_bytes_atomic(f"jointcal: {exc}\n".encode(), RESULTS / "logs" / "ingest.log")
            sys.exit(f"jointcal: {exc}")
    return _CHECKED[0]


def campaign_files(wildcards):
    """The manifest and every run file it lists, once the manifest is checked (checked_campaign)."""
    checked_campaign()
    return {"manifest": str(MANIFEST), "runs": list(RUN_FILES.values())}


def campaign_records(wildcards):
    """Every run file the manifest lists, once the manifest is checked."""
    checked_campaign()
    return list(RUN_FILES.values())


def run_record(wildcards):
    """The raw record of one run, once the manifest is checked."""
    checked_campaign()
    return RUN_FILES[wildcards.run_id]


def ingest_table(wildcards):
    """The ingest stage's runs.csv when the workflow has that stage (one of calibrate + posterior only has not)."""
    return [str(RESULTS / "ingest" / "runs.csv")] if has_rule("ingest") else []


def has_rule(name):
    """Whether this workflow defines rule `name` (called when the DAG is built, after every include)."""
    from snakemake.exceptions import WorkflowError

    try:
        getattr(rules, name)
    except (WorkflowError, AttributeError):
        return False
    return True


def verdict_inputs(wildcards):
    """The later stages' outputs the verdict reads, for the stages this workflow has."""
    out = {}
    if has_rule("validate_assembly"):
        out["validation"] = [str(RESULTS / "validation" / a / "summary.json") for a in ASSEMBLIES]
    if has_rule("discrepancy_assembly") and EXCITATION == "base":
        out["diagnosis"] = [str(RESULTS / "discrepancy" / a / "diagnosis.json") for a in ASSEMBLIES]
    if has_rule("design_assembly"):
        out["design"] = [str(RESULTS / "design" / a / "next_test.json") for a in ASSEMBLIES]
    return out


def assembly_records(wildcards):
    """The raw records of one assembly's runs, once the manifest is checked."""
    table = checked_campaign()
    return [RUN_FILES[rid] for rid, asm in zip(table["run_id"], table["assembly"]) if asm == wildcards.assembly]


def remove_stale_outputs():
    """After a failed run, remove the outputs of every job the run had scheduled and did not finish.

    Snakemake deletes the outputs of the job that failed; those of the previous run further down
    (calibration, posterior, figures, table) would stay and look current. A job scheduled to rerun
    has outdated outputs (its inputs, code hash or params changed, or an upstream job reran), so
    they go; finished jobs, logs, benchmarks and the GA/chain checkpoints stay (a rerun resumes).
    """
    try:  # Snakemake 9's DAG (workflow.dag, DAG.needrun_jobs)
        jobs = list(workflow.dag.needrun_jobs(exclude_finished=True))
    except AttributeError:
        print("jointcal: the run failed; outputs of jobs that did not run may be out of date "
              "(this Snakemake version does not show which)", file=sys.stderr)
        return
    stale = [Path(f) for job in jobs for f in job.output if os.path.isfile(f)]
    for f in stale:
        f.unlink(missing_ok=True)
    if stale:
        shown = ", ".join(str(f) for f in stale[:4]) + (f" and {len(stale) - 4} more" if len(stale) > 4 else "")
        print(f"jointcal: the run failed; removed {len(stale)} outputs of jobs that did not run to the end, "
              f"so nothing out of date looks current: {shown}", file=sys.stderr)


onerror:
    remove_stale_outputs()
