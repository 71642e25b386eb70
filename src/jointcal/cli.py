"""Command line: ``jointcal <subcommand> ...`` (also ``python -m jointcal.cli``).

Each subcommand is one ``_cmd_<name>(args) -> int`` function plus one entry in
`build_parser`. A `~jointcal.io.CampaignError` (or a path that cannot be read or written)
prints ``jointcal: <message>`` to stderr and exits with status 2, having written
nothing: user errors never print a traceback.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

from jointcal import __version__
from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, write_csv_atomic

__all__ = ["build_parser", "main"]


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


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand (each sets ``func``)."""
    parser = argparse.ArgumentParser(
        prog="jointcal", description="Calibrate Iwan joint models from swept-sine shaker tests.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
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
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 ok, 2 bad campaign or usage).

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
