"""The full example reproduction: `snakemake --cores 2` from a fresh clone, and a per-stage breakdown.

Clones the repository's committed HEAD into a temporary folder and runs the workflow there as
a user would, with the clone's own package on PYTHONPATH (so numba compiles its kernels into the
clone's empty cache, as on a fresh install). Prints the wall time against the 120 s target and
the load average seen, then one line per stage: when its first job started and its last ended
(from Snakemake's log; the stages overlap, since jobs run side by side on the cores), its jobs,
their summed and longest wall time and CPU time, and the largest resident memory, from
Snakemake's ``benchmark:`` files (<results>/benchmarks/). With ``--reference DIR`` (the results
of an earlier run, e.g. before a change) each stage's summed wall time is also given as a ratio
to that run's. With ``--results DIR`` it only tabulates an earlier run.

    python tests/benchmarks/bench_workflow.py [--reference OLD_RESULTS] [--keep]
    python tests/benchmarks/bench_workflow.py --results results
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]
TARGET_S = 120.0
# stage of each rule, in the order data flows (a rule not listed is its own stage)
STAGES = {"ingest": "ingest", "envelopes_runs": "envelopes", "envelopes_run": "envelopes",
          "modal_properties": "modal", "modal_figures": "modal",
          "calibrate_assembly": "calibrate", "calibrate": "calibrate", "calibration_figures": "calibrate",
          "posterior_assembly": "posterior", "posterior": "posterior", "posterior_corner": "posterior",
          "posterior_report": "posterior", "validate_assembly": "validate", "validate_figures": "validate",
          "discrepancy_assembly": "discrepancy", "discrepancy_table": "discrepancy",
          "design_assembly": "design", "report_summary": "summary"}


def _rule_of(results: Path, f: Path) -> str:
    """The rule of a benchmark file (<rule>.tsv, <rule>/<wildcards>.tsv, or the older <rule>_<assembly>.tsv)."""
    first = f.relative_to(results / "benchmarks").parts[0].removesuffix(".tsv")
    if first in STAGES:
        return first
    return next((r for r in STAGES if first.startswith(r.split("_")[0] + "_")), first)


def breakdown(results: Path, timeline: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per-stage table from <results>/benchmarks/ (and the start/end of each stage from `timeline`)."""
    rows = []
    for f in sorted((results / "benchmarks").rglob("*.tsv")):
        b = pd.read_csv(f, sep="\t").iloc[-1]
        rule = _rule_of(results, f)
        rows.append(dict(stage=STAGES.get(rule, rule), s=float(b["s"]), cpu_s=float(b["cpu_time"]),
                         max_rss_mb=float(b["max_rss"])))
    df = pd.DataFrame(rows)
    order = list(dict.fromkeys(STAGES.values()))
    table = (df.groupby("stage", sort=False)
               .agg(jobs=("s", "size"), wall_s=("s", "sum"), longest_s=("s", "max"), cpu_s=("cpu_s", "sum"),
                    max_rss_mb=("max_rss_mb", "max")))
    table = table.loc[sorted(table.index, key=lambda s: order.index(s) if s in order else len(order))]
    if timeline is not None and len(timeline):
        t = timeline.assign(stage=timeline["rule"].map(lambda r: STAGES.get(r, r)))
        span = t.groupby("stage").agg(from_s=("start", "min"), to_s=("end", "max"))
        table = span.join(table, how="right")
    return table


def timeline(log: str) -> pd.DataFrame:
    """Start and end (s after the first job's start) of every job in Snakemake's log text."""
    stamp, rule, start, rows = None, None, {}, []
    for line in log.splitlines():
        if m := re.match(r"\[(\w{3} \w{3} +\d+ [\d:]+ \d{4})\]", line):
            stamp = datetime.strptime(m.group(1), "%a %b %d %H:%M:%S %Y")
        elif m := re.match(r"(?:local)?rule (\w+):", line):
            rule = m.group(1)
        elif (m := re.match(r"\s+jobid: (\d+)", line)) and rule:
            start[m.group(1)], rule = (rule, stamp), None
        elif (m := re.match(r"Finished jobid: (\d+)", line)) and m.group(1) in start:
            r, s = start.pop(m.group(1))
            rows.append(dict(rule=r, start=s, end=stamp))
    df = pd.DataFrame(rows, columns=["rule", "start", "end"])
    if len(df):
        t0 = df["start"].min()
        df["start"] = (df["start"] - t0).dt.total_seconds()
        df["end"] = (df["end"] - t0).dt.total_seconds()
    return df


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, help="tabulate this results folder instead of running")
    ap.add_argument("--reference", type=Path, help="results folder of an earlier run: ratios of the stages to it")
    ap.add_argument("--keep", action="store_true", help="keep the temporary clone and print its path")
    args = ap.parse_args()
    if args.results is not None:
        print(breakdown(args.results).round(1).to_string())
        return
    work = Path(tempfile.mkdtemp(prefix="jointcal-bench-")) / "jointcal"
    subprocess.run(["git", "clone", "--quiet", "--no-hardlinks", str(REPO), str(work)], check=True)
    env = {**os.environ, "PYTHONPATH": str(work / "src")}  # the clone's package, its numba cache empty
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2"], cwd=work, capture_output=True,
                         text=True, env=env)
    wall = time.perf_counter() - t0
    load1 = os.getloadavg()
    if res.returncode != 0:
        sys.exit(f"the workflow failed after {wall:.0f} s:\n{res.stderr[-3000:]}")
    table = breakdown(work / "results", timeline(res.stderr))
    if args.reference is not None:
        ref = breakdown(args.reference)
        table["x_reference"] = table["wall_s"] / ref["wall_s"].reindex(table.index)
    print(f"snakemake --cores 2 on the example campaign, fresh clone: {wall:.0f} s wall "
          f"({wall / TARGET_S:.2f} x the {TARGET_S:.0f} s target); jobs' CPU time {table['cpu_s'].sum():.0f} s; "
          f"load average {load0:.1f} at the start, {load1[0]:.1f} at the end ({load1[1]:.1f} over 5 min)")
    print(table.round(2).to_string())
    for log in sorted((work / "results" / "logs" / "posterior").glob("*.log")):
        print(f"{log.stem}: " + next((ln for ln in log.read_text().splitlines() if "emcee:" in ln), "(no summary)"))
    if args.keep:
        print(f"kept: {work}")
    else:
        shutil.rmtree(work.parent)


if __name__ == "__main__":
    main()
