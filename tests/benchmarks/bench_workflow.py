"""The full example reproduction: `snakemake --cores 2` from scratch, and a per-stage breakdown.

Copies Snakefile, workflow/ and profiles/ to a temporary folder, links raw_data/, runs the
workflow as a user would (the package imported is the one on PYTHONPATH / installed), and
prints the wall time against the 5-minute target, then one line per rule from Snakemake's
``benchmark:`` files (<results>/benchmarks/): jobs, summed and longest job wall time, CPU
time, largest resident memory. With ``--results DIR`` it only tabulates an earlier run.

    python tests/benchmarks/bench_workflow.py [--results results] [--keep]
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]
TARGET_S = 300.0


def breakdown(results: Path) -> pd.DataFrame:
    """Per-rule table from <results>/benchmarks/<rule>.tsv or <rule>/<wildcard>.tsv."""
    rows = []
    for f in sorted((results / "benchmarks").rglob("*.tsv")):
        rule = f.relative_to(results / "benchmarks").parts[0].removesuffix(".tsv")
        b = pd.read_csv(f, sep="\t").iloc[-1]
        rows.append(dict(rule=rule, s=float(b["s"]), cpu_s=float(b["cpu_time"]), max_rss_mb=float(b["max_rss"])))
    df = pd.DataFrame(rows)
    return (df.groupby("rule", sort=False)
              .agg(jobs=("s", "size"), wall_s=("s", "sum"), longest_s=("s", "max"), cpu_s=("cpu_s", "sum"),
                   max_rss_mb=("max_rss_mb", "max"))
              .sort_values("wall_s", ascending=False))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, help="tabulate this results folder instead of running")
    ap.add_argument("--keep", action="store_true", help="keep the temporary copy and print its path")
    args = ap.parse_args()
    if args.results is not None:
        print(breakdown(args.results).round(1).to_string())
        return
    work = Path(tempfile.mkdtemp(prefix="jointcal-bench-"))
    shutil.copy(REPO / "Snakefile", work)
    for folder in ("workflow", "profiles"):
        shutil.copytree(REPO / folder, work / folder, symlinks=True, ignore=shutil.ignore_patterns("__pycache__"))
    (work / "raw_data").symlink_to(REPO / "raw_data")
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2"], cwd=work, capture_output=True,
                         text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"the workflow failed after {wall:.0f} s:\n{res.stderr[-3000:]}")
    table = breakdown(work / "results")
    print(f"snakemake --cores 2 on the example campaign, from scratch: {wall:.0f} s wall "
          f"({wall / TARGET_S:.2f} x the {TARGET_S:.0f} s target); jobs' CPU time {table['cpu_s'].sum():.0f} s")
    print(table.round(1).to_string())
    for log in sorted((work / "results" / "logs" / "posterior").glob("*.log")):
        print(f"{log.stem}: " + next((ln for ln in log.read_text().splitlines() if "emcee:" in ln), "(no summary)"))
    if args.keep:
        print(f"kept: {work}")
    else:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
