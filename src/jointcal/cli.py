"""Command line: ``jointcal <subcommand> ...`` (also ``python -m jointcal.cli``).

Each subcommand is one ``_cmd_<name>(args) -> int`` function plus one entry in
`build_parser`. A `~jointcal.io.CampaignError` (or a path that cannot be read or written)
prints ``jointcal: <message>`` to stderr and exits with status 2, having written
nothing: user errors never print a traceback.

The stage subcommands (``envelopes``, ``modal``, ``unit``, ``calibrate``, ``posterior``, ``validate``,
``discrepancy``, ``design``) run a workflow stage without Snakemake: the same function the stage's
script calls (``workflow/scripts/<stage>.py``), on files named on the command line, with the
settings of ``workflow/config/config.yaml`` merged with ``--config FILE`` as Snakemake's
``--configfile`` merges them and checked against the workflow's schema. The stage's log lines go to
stdout, its warnings to stderr, and an error of its inputs or settings (a `ValueError`) is one
sentence on stderr and exit status 2.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

from typing import Any

from jointcal import __version__
from jointcal._stage_job import Job, console_job
from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, write_csv_atomic

__all__ = ["build_parser", "main", "read_config"]

_WORKFLOW = Path(__file__).resolve().parents[2] / "workflow"  # in a source checkout (pip install -e .)


def _cmd_ingest(args: argparse.Namespace) -> int:
    """Validate a campaign folder and write one row per run to OUT_CSV."""
    out = Path(args.out_csv)
    if out.is_dir():
        raise CampaignError(f"{out}: OUT_CSV is a folder; give the table's file name, e.g. {out / 'runs.csv'}.")
    runs = ingest_campaign(args.campaign_dir, on_data_problem=args.on_data_problem)
    campaign = Path(args.campaign_dir)
    inputs = [campaign / "manifest.csv", *(campaign / f for f in runs["file"])]
    if out.exists() and any(out.resolve() == p.resolve() for p in inputs):
        raise CampaignError(f"{out}: OUT_CSV is an input of the campaign and would be overwritten; "
                            "write the table elsewhere, e.g. runs.csv.")
    write_csv_atomic(runs, args.out_csv)
    flagged = int((runs["flags"] != "").sum())
    print(f"jointcal: wrote {len(runs)} runs ({flagged} flagged) to {args.out_csv}")
    return 0


def _cmd_synth(args: argparse.Namespace) -> int:
    """Generate a synthetic campaign from a truth spec; write the truth outside it."""
    import time

    from jointcal.synth import generate

    t0 = time.perf_counter()
    try:
        table = generate(args.spec, args.out_dir, args.truth)
    except ValueError as exc:
        print(f"jointcal: {exc}", file=sys.stderr)
        return 2
    print(f"jointcal: wrote {len(table)} runs to {args.out_dir} and the truth to {args.truth} "
          f"in {time.perf_counter() - t0:.1f} s")
    return 0


def read_config(path: str | Path | None = None) -> dict[str, Any]:
    """The workflow's config as Snakemake reads it: ``workflow/config/config.yaml``, then `path` merged over it.

    Parameters
    ----------
    path : path-like, optional
        A YAML file holding only what changes (as ``snakemake --configfile``); nested sections are merged
        key by key.

    Returns
    -------
    dict
        The merged config, checked against ``workflow/schemas/config.schema.yaml``. Without the
        ``workflow/`` folder (jointcal installed from a wheel) the defaults are empty sections, whose
        settings default to the same values.

    Raises
    ------
    ValueError
        A key that is not a setting, or a value the schema rejects (one sentence).
    """
    import yaml
    from snakemake.utils import update_config

    from jointcal._workflow import config_problem

    defaults = _WORKFLOW / "config" / "config.yaml"
    config = yaml.safe_load(defaults.read_text()) if defaults.is_file() else {}
    if path is not None:
        update_config(config, yaml.safe_load(Path(path).read_text()) or {})
    schema = _WORKFLOW / "schemas" / "config.schema.yaml"
    if schema.is_file() and (problem := config_problem(config, schema)):
        raise ValueError(f"{path or defaults}: {problem}")
    return config


def _records(campaign_dir: str, assembly: str | None = None) -> list[str]:
    """The campaign's record files as the workflow lists them (all, or one assembly's runs)."""
    from jointcal._campaign_index import campaign_index

    index = campaign_index(Path(campaign_dir) / "manifest.csv")
    if index.problem:
        raise CampaignError(index.problem)
    if assembly is not None:
        return index.assembly_files(assembly)
    return list(index.run_files.values()) + list(index.reference_files)


def _run_ids(runs_csv: str) -> list[str]:
    import pandas as pd

    return [str(r) for r in pd.read_csv(runs_csv, dtype={"run_id": str})["run_id"]]


def _cmd_envelopes(args: argparse.Namespace) -> int:
    """Every run's envelopes and metadata (<run_id>.csv, .json) in OUT (rule envelopes_runs)."""
    from jointcal.measure.envelopes_stage import run_envelopes

    config, out, ids = read_config(args.config), Path(args.out), _run_ids(args.runs)
    with console_job(args.threads) as job:
        run_envelopes(args.runs, _records(args.campaign_dir), config["envelopes"], [out / f"{r}.csv" for r in ids],
                      [out / f"{r}.json" for r in ids], mapper=job.map, log=job.log, warn=job.warn)
    return 0


def _cmd_modal(args: argparse.Namespace) -> int:
    """modal_properties.csv, scatter.csv, backbone.csv and frf/ in OUT (rule modal_properties)."""
    from jointcal.measure.stage import run_modal

    config, out, env = read_config(args.config), Path(args.out), Path(args.envelopes)
    with console_job() as job:
        run_modal(args.runs, [env / f"{r}.csv" for r in _run_ids(args.runs)], _records(args.campaign_dir),
                  config["modal"], table_csv=out / "modal_properties.csv", scatter_csv=out / "scatter.csv",
                  backbone_csv=out / "backbone.csv", frf_dir=out / "frf", warn=job.warn, log=job.log)
    return 0


def _cmd_unit(args: argparse.Namespace) -> int:
    """One (assembly, mode)'s rows of the modal tables in MODAL_DIR/<assembly>/<mode>/ (rule modal_unit)."""
    from jointcal.measure.stage import run_modal_unit

    modal = Path(args.modal_dir)
    out = Path(args.out) if args.out else modal / args.assembly / args.mode
    with console_job() as job:
        job.log(run_modal_unit(modal / "modal_properties.csv", modal / "scatter.csv", modal / "backbone.csv",
                               args.assembly, args.mode, unit_table_csv=out / "modal_properties.csv",
                               unit_scatter_csv=out / "scatter.csv", unit_backbone_csv=out / "backbone.csv"))
    return 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    """ga_best.json, ga_history.csv, ga_logbook.csv, model_curves.csv in OUT (rule calibrate_assembly)."""
    from jointcal.calibrate import CalibrateSettings, run_calibration

    config = read_config(args.config)
    with console_job() as job:
        settings = CalibrateSettings.from_config(config.get("calibrate", {}))
        _, notes = run_calibration(args.modal, args.assembly, args.out, settings, checkpoint=args.checkpoint,
                                   progress=job.log, backbone_csv=args.backbone)
        for n in notes:
            job.log(n)
    return 0


def _cmd_posterior(args: argparse.Namespace) -> int:
    """summary.csv, chain.npz, constraints.txt, predictive.csv, identified.csv in OUT (rule posterior_assembly)."""
    from jointcal.posterior.unit_stage import run_posterior_unit

    config, out = read_config(args.config), Path(args.out)
    with console_job() as job:
        run_posterior_unit(args.modal, args.scatter, args.backbone, args.best, args.assembly,
                           summary_csv=out / "summary.csv", chain_npz=out / "chain.npz",
                           identified_csv=out / "identified.csv", calibrate=config.get("calibrate", {}),
                           posterior=config.get("posterior", {}), checkpoint=args.checkpoint, log=job.log,
                           warn=job.warn)
    return 0


def _cmd_validate(args: argparse.Namespace) -> int:
    """metrics.csv, summary.json and envelopes/ in OUT (rule validate_assembly)."""
    from jointcal.validate.stage import run_validation

    config, out = read_config(args.config), Path(args.out)
    with console_job(args.threads) as job, job.pool() as ex:
        run_validation(args.best, args.runs, args.modal, args.chain, _records(args.campaign_dir, args.assembly),
                       args.assembly, config.get("validate", {}), metrics_csv=out / "metrics.csv",
                       summary_json=out / "summary.json", envelopes_dir=out / "envelopes",
                       envelopes_kw=config["envelopes"], modal_kw=config["modal"], executor=ex,
                       workers=job.workers(), log=job.log, warn=job.warn)
    return 0


def _cmd_discrepancy(args: argparse.Namespace) -> int:
    """diagnosis.json, diagnosis.md, residuals.csv, metrics_after.csv and two figures in OUT (rule
    discrepancy_assembly)."""
    from jointcal.discrepancy.stage import run_discrepancy

    config, out, env = read_config(args.config), Path(args.out), Path(args.envelopes)
    sections = {k: config.get(k, {}) for k in ("discrepancy", "calibrate", "validate", "envelopes", "modal")}
    files = {"diagnosis": "diagnosis.json", "markdown": "diagnosis.md", "residuals": "residuals.csv",
             "metrics_after": "metrics_after.csv", "residual_figure": "discrepancy_residuals.png",
             "before_after_figure": "discrepancy_before_after.png"}
    with console_job(args.threads) as job, job.pool() as ex:
        d = run_discrepancy(args.assembly, runs_csv=args.runs, modal_csv=args.modal,
                            envelope_files=[str(env / f"{r}.csv") for r in _run_ids(args.runs)],
                            record_files=_records(args.campaign_dir, args.assembly), best_json=args.best,
                            history_csv=args.history, validation_json=args.validation,
                            out={k: str(out / f) for k, f in files.items()}, config=sections, executor=ex,
                            log=job.log)
        job.log(f"{args.assembly}: {d['effect']} ({d['confidence']}); E {d['metric_before']:.2f} -> "
                f"{d['metric_after']:.2f}; {d['seconds']:.0f} s")
    return 0


def _cmd_design(args: argparse.Namespace) -> int:
    """next_test.json, next_test.csv, next_test.md and next_test.png in OUT (rule design_assembly)."""
    from jointcal.design.stage import run_design_unit

    config, out = read_config(args.config), Path(args.out)
    with console_job() as job:
        line = run_design_unit(args.runs, args.modal, args.scatter, args.best, args.chain, args.identified,
                               args.assembly, out, figure_png=out / "next_test.png", design=config.get("design", {}),
                               calibrate=config.get("calibrate", {}), posterior=config.get("posterior", {}),
                               modal=config["modal"])
        job.log(f"{args.assembly}: {line} ({job.elapsed:.1f} s)")
    return 0


_FILES = {  # the stage subcommands' input options: metavar, help
    "runs": ("CSV", "ingest's runs.csv"),
    "envelopes": ("DIR", "folder of the envelope stage's <run_id>.csv files"),
    "modal": ("CSV", "the unit's modal_properties.csv (jointcal unit)"),
    "scatter": ("CSV", "the unit's scatter.csv (jointcal unit)"),
    "backbone": ("CSV", "the unit's backbone.csv (jointcal unit): ring-down and dwell read-outs"),
    "best": ("JSON", "the calibration's ga_best.json"),
    "history": ("CSV", "the calibration's ga_history.csv"),
    "chain": ("NPZ", "the posterior's chain.npz"),
    "identified": ("CSV", "the posterior's identified.csv"),
    "validation": ("JSON", "the validation's summary.json (its envelopes/ beside it)"),
    "assembly": ("NAME", "the assembly (the manifest's assembly column)"),
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand (each sets ``func``)."""
    parser = argparse.ArgumentParser(
        prog="jointcal", description="Calibrate Iwan joint models from swept-sine shaker tests.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.set_defaults(errors=())
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("ingest", help="validate a campaign folder and tabulate its runs",
                       description=_cmd_ingest.__doc__)
    p.add_argument("campaign_dir", metavar="CAMPAIGN_DIR", help="folder holding manifest.csv and the run files")
    p.add_argument("out_csv", metavar="OUT_CSV", help="table to write (one row per run)")
    p.add_argument("--on-data-problem", choices=("error", "flag"), default="error",
                   help="data problems (NaN/inf, clipping, dead or swapped channels, amplitude off the level): "
                        "fail (default) or record them in the flags column")
    p.set_defaults(func=_cmd_ingest)

    p = sub.add_parser("synth", help="generate a synthetic campaign (virtual shaker lab) from a truth spec",
                       description=_cmd_synth.__doc__)
    p.add_argument("spec", metavar="SPEC", help="truth spec, YAML or JSON (see jointcal.synth.spec)")
    p.add_argument("out_dir", metavar="OUT", help="campaign folder to write (manifest.csv + runs/)")
    p.add_argument("--truth", required=True, metavar="TRUTH_JSON",
                   help="where to write the truth (parameters, effect, per-run resonance); outside OUT")
    p.set_defaults(func=_cmd_synth)

    def stage(name: str, cmd, summary: str, *, errors: tuple[type[BaseException], ...] = (ValueError,),
              threads: bool = False) -> argparse.ArgumentParser:
        """A stage's subparser: --config, --out (and --threads), errors of `errors` to one sentence."""
        p = sub.add_parser(name, help=summary, description=cmd.__doc__)
        p.add_argument("--config", metavar="YAML", help="settings merged over workflow/config/config.yaml "
                                                        "(as snakemake --configfile)")
        p.add_argument("--out", required=True, metavar="DIR", help="folder the stage writes")
        if threads:
            p.add_argument("--threads", type=int, default=1, metavar="N", help="processes to use (default 1)")
        p.set_defaults(func=cmd, errors=errors)
        return p

    def files(p: argparse.ArgumentParser, *names: str) -> None:
        for n in names:
            p.add_argument(f"--{n}", required=True, metavar=_FILES[n][0], help=_FILES[n][1])

    p = stage("envelopes", _cmd_envelopes, "every run's envelopes (stage envelopes)", threads=True)
    p.add_argument("campaign_dir", metavar="CAMPAIGN_DIR", help="folder holding manifest.csv and the run files")
    files(p, "runs")
    p = stage("modal", _cmd_modal, "every run's read-outs per mode (stage modal)")
    p.add_argument("campaign_dir", metavar="CAMPAIGN_DIR", help="folder holding manifest.csv and the run files")
    files(p, "runs", "envelopes")
    p = sub.add_parser("unit", help="one (assembly, mode)'s rows of the modal tables (rule modal_unit)",
                       description=_cmd_unit.__doc__)
    p.add_argument("modal_dir", metavar="MODAL_DIR", help="folder of jointcal modal's tables")
    p.add_argument("--assembly", required=True)
    p.add_argument("--mode", required=True, help="the mode's name in modal_properties.csv, e.g. m18")
    p.add_argument("--out", metavar="DIR", help="folder the unit's tables go to (default MODAL_DIR/ASSEMBLY/MODE)")
    p.set_defaults(func=_cmd_unit, errors=(ValueError,))
    p = stage("calibrate", _cmd_calibrate, "GA on eq. 3.9 for one unit (stage calibrate)")
    files(p, "modal", "assembly")
    p.add_argument("--backbone", metavar="CSV", help=_FILES["backbone"][1])
    p.add_argument("--checkpoint", metavar="PKL", help="GA checkpoint: resumed from when it matches")
    p = stage("posterior", _cmd_posterior, "emcee around the GA optimum of one unit (stage posterior)")
    files(p, "modal", "scatter", "backbone", "best", "assembly")
    p.add_argument("--checkpoint", metavar="NPZ", help="chain checkpoint: resumed from when it matches")
    p = stage("validate", _cmd_validate, "the calibrated model driven by each measured run (stage validate)",
              threads=True)
    p.add_argument("campaign_dir", metavar="CAMPAIGN_DIR", help="folder holding manifest.csv and the run files")
    files(p, "runs", "modal", "best", "chain", "assembly")
    p = stage("discrepancy", _cmd_discrepancy, "name the effect the model misses (stage discrepancy)", threads=True)
    p.add_argument("campaign_dir", metavar="CAMPAIGN_DIR", help="folder holding manifest.csv and the run files")
    files(p, "runs", "modal", "envelopes", "best", "history", "validation", "assembly")
    p = stage("design", _cmd_design, "the next test of one unit (stage design)")
    files(p, "runs", "modal", "scatter", "best", "chain", "identified", "assembly")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 ok, 2 bad campaign, input, setting or usage).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when None.
    """
    args = build_parser().parse_args(argv)
    error = ""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CampaignWarning)
        try:
            status = args.func(args)
        except CampaignError as exc:
            error, status = f"jointcal: {exc}", 2
        except args.errors as exc:  # a stage's input or setting (its one sentence)
            error, status = f"jointcal: {exc}", 2
        except OSError as exc:  # a path the user gave cannot be read or written
            where = exc.filename if exc.filename is not None else "a file"
            error, status = f"jointcal: {where}: {exc.strerror or exc}; check the path and its permissions.", 2
    for w in caught:  # every warning, also when an error follows
        if issubclass(w.category, CampaignWarning):
            print(f"jointcal: warning: {w.message}", file=sys.stderr)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    if error:
        print(error, file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
