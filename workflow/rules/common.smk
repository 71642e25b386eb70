# Shared names, paths and input functions of the jointcal workflow (logic lives in src/jointcal/); every
# stage's file uses them, so the stage files may be included in any order after this one.
import re
import subprocess
import sys
import time
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from jointcal._workflow import campaign_index, config_problem, modal_units, pending_outputs, stage_hashes, unit_outputs
from jointcal.io import write_bytes_atomic

# Config: an unknown key (a typo) is one line naming the nearest valid key, before the schema's own
# validation (whose message is a dump of the schema); nested --config values given as text are converted.
SCHEMA = Path(workflow.current_basedir).parent / "schemas" / "config.schema.yaml"
if problem := config_problem(config, SCHEMA):
    sys.exit(f"jointcal: {problem}")
validate(config, SCHEMA)

SCRIPTS = Path(workflow.current_basedir).parent / "scripts"
_SCRIPT_FILES = sorted(SCRIPTS.glob("*.py"))
SOURCE_HASHES = dict(zip((f.name for f in _SCRIPT_FILES), stage_hashes(_SCRIPT_FILES)))  # every stage's, in one pass


def source_hash(script):
    """Content hash of a stage script and every jointcal module it imports (jointcal._workflow.stage_hash).

    Passed as a rule's params, so a change to the code a stage runs reruns that stage and its
    descendants (Snakemake's params trigger); a package version nobody bumps would not.
    """
    return SOURCE_HASHES[script]


RAW_DATA = Path(config["raw_data"])
RESULTS = Path(config["results"])
MANIFEST = RAW_DATA / "manifest.csv"
if not MANIFEST.is_file():
    sys.exit(
        f"jointcal: {MANIFEST}: the campaign manifest does not exist; put the campaign "
        "(manifest.csv and run files, see raw_data/README.md) there or point to it "
        "with --config raw_data=PATH/TO/CAMPAIGN."
    )

# The campaign, read once with jointcal.io.read_manifest (jointcal._workflow.campaign_index): a manifest
# that fails its checks still names the jobs, and the rules that read raw records stop on its error.
CAMPAIGN = campaign_index(MANIFEST)
RUN_FILES = CAMPAIGN.run_files
RUN_IDS = list(RUN_FILES)
ASSEMBLIES = CAMPAIGN.assemblies
ASSEMBLY_RE = "|".join(re.escape(a) for a in ASSEMBLIES) or "no-assembly"
EXCITATION = CAMPAIGN.excitation  # base, force or voltage, from the manifest's level column
MODE_RE = r"m\d+(?:_\d+p\d)?"  # a mode's name (jointcal.measure.modes.mode_name): m18, m95

# Each stage's folder under RESULTS (stages in the order data flows).
INGEST = RESULTS / "ingest"
ENVELOPES = RESULTS / "envelopes"
MODAL = RESULTS / "modal"
CALIBRATION = RESULTS / "calibration"
POSTERIOR = RESULTS / "posterior"
VALIDATION = RESULTS / "validation"
DISCREPANCY = RESULTS / "discrepancy"
KERNELS = RESULTS / "kernels" / "numba.txt"  # the numba kernels compiled (kernels.smk)
DESIGN = RESULTS / "design"
FIGURES = RESULTS / "figures"
REPORT = RESULTS / "report"  # the summary page and the run-generated captions


def pool_threads(wildcards):
    """Threads of a per-assembly job that spreads its runs over a process pool (validate, discrepancy): the
    cores shared among the assemblies, so the assemblies' jobs run side by side (most of such a job is one
    process; its pool serves part of it), and all of them for a campaign of one assembly."""
    try:
        cores = int(workflow.cores)
    except (WorkflowError, TypeError, ValueError):  # no --cores (a dry run or --lint)
        return 1
    return max(1, min(cores, 64) // max(1, len(ASSEMBLIES)))


def units():
    """The (assembly, mode) pairs the stages after modal run on, from the modal checkpoint's table
    (jointcal._workflow.modal_units: each mode read at two levels or more)."""
    if has_rule("modal_properties"):
        return modal_units(checkpoints.modal_properties.get().output.table)
    return modal_units(MODAL / "modal_properties.csv")  # a workflow of the later stages, on their tables


def unit_files(*patterns):
    """An input function: each pattern (with {assembly} and {mode}) for every unit of the campaign."""

    def files(wildcards):
        return [str(p).format(assembly=a, mode=m) for p in patterns for a, m in units()]

    return files


def checked_campaign():
    """Stop on the manifest's problem, if it has one, in the input function of every rule that reads raw
    records: a Windows path, a listed file that is missing or any other manifest problem stops the workflow
    there with the one-sentence message on stderr and in the ingest log, before Snakemake looks for the
    records (its MissingInputException names no fix). Notes on the manifest (empty trailing rows) are left
    to the ingest stage's log."""
    if CAMPAIGN.problem:
        write_bytes_atomic(f"jointcal: {CAMPAIGN.problem}\n".encode(), RESULTS / "logs" / "ingest.log")
        sys.exit(f"jointcal: {CAMPAIGN.problem}")
    return CAMPAIGN


def campaign_files(wildcards):
    """The manifest and every run file it lists (with its reference files), once it is checked (checked_campaign)."""
    checked_campaign()
    return {"manifest": str(MANIFEST), "runs": list(RUN_FILES.values()) + list(CAMPAIGN.reference_files)}


def campaign_records(wildcards):
    """Every run file the manifest lists (and the lab exports holding references apart), once it is checked."""
    checked_campaign()
    return list(RUN_FILES.values()) + list(CAMPAIGN.reference_files)


def run_record(wildcards):
    """The raw record of one run, once the manifest is checked."""
    checked_campaign()
    return RUN_FILES[wildcards.run_id]


def ingest_table(wildcards):
    """The ingest stage's runs.csv when the workflow has that stage (one of calibrate + posterior only has not)."""
    return [str(INGEST / "runs.csv")] if has_rule("ingest") else []


def has_rule(name):
    """Whether this workflow defines rule `name` (called when the DAG is built, after every include)."""
    try:
        getattr(rules, name)
    except (WorkflowError, AttributeError):
        return False
    return True


def verdict_inputs(wildcards):
    """The later stages' outputs the verdict reads, for the stages this workflow has."""
    out = {}
    if has_rule("validate_assembly"):
        out["validation"] = [str(VALIDATION / a / m / "summary.json") for a, m in units()]
    if has_rule("discrepancy_assembly"):
        out["diagnosis"] = [str(DISCREPANCY / a / m / "diagnosis.json") for a, m in units()]
    if has_rule("design_assembly"):
        out["design"] = [str(DESIGN / a / m / "next_test.json") for a, m in units()]
    return out


def assembly_records(wildcards):
    """The raw records of one assembly's runs, once the manifest is checked."""
    return checked_campaign().assembly_files(wildcards.assembly)


STARTED = time.time()  # when this run parsed the workflow: outputs written since are this run's


def remove_stale_outputs():
    """After a failed run, remove the outputs the same command still plans to remake and this run did not.

    Snakemake deletes the outputs of the job that failed; those of the previous run further down
    (calibration, posterior, figures, table) would stay and look current. Snakemake's own summary of the
    same command (``--summary``: the plan for each output file) names the outputs whose jobs are still to
    run (their inputs, code hash or params changed, or an upstream job reran or failed), so those
    written before this run go; finished jobs, logs, benchmarks and the GA/chain checkpoints stay (a
    rerun resumes).
    """
    kept = {"logs", "benchmarks", "checkpoints"}  # never outputs of a job
    if not any(f.is_file() and f.stat().st_mtime < STARTED for f in RESULTS.rglob("*")
               if not kept & set(f.relative_to(RESULTS).parts[:1])):
        return  # nothing from before this run that could be out of date (e.g. a first run that failed)
    cli = Path(sys.argv[0])
    if not (cli.name == "snakemake" or cli.parent.name == "snakemake"):  # run through an API: no command
        print("jointcal: the run failed; outputs of jobs that did not run may be out of date", file=sys.stderr)
        return
    summary = subprocess.run([sys.executable, "-m", "snakemake", *sys.argv[1:], "--summary", "--nolock"],
                             capture_output=True, text=True)
    stale = pending_outputs(summary.stdout, before=STARTED)
    table = MODAL / "modal_properties.csv"
    if not table.is_file() or table.resolve() in {f.resolve() for f in stale}:  # the summary cannot list the jobs its table names
        stale += [f for f in unit_outputs(RESULTS, before=STARTED) if f not in stale]
    for f in stale:
        f.unlink(missing_ok=True)
    if stale:
        shown = ", ".join(str(f) for f in stale[:4]) + (f" and {len(stale) - 4} more" if len(stale) > 4 else "")
        print(f"jointcal: the run failed; removed {len(stale)} outputs of jobs that did not run to the end, "
              f"so nothing out of date looks current: {shown}", file=sys.stderr)


onerror:
    remove_stale_outputs()
