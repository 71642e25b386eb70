"""Two results/ trees of the workflow compared: every file byte for byte, tables and JSON value by value.

A change meant for speed alone must leave the example's outputs as they were. This reads two results
folders (e.g. `bench_workflow.py --keep` runs before and after the change), skips the logs and
Snakemake's benchmark files, and prints each file that differs with the columns (csv) or keys (json,
list indices folded) that differ. The timing fields (`TIMING`: a stage's own clock) may differ; any
other difference, or a file in one tree alone, makes the exit status 1.

    python tests/benchmarks/compare_results.py OLD_RESULTS NEW_RESULTS
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

SKIP = {"benchmarks", "logs"}
TIMING = {"sim_s", "compare_s", "draws_s", "wall_s", "seconds", "/seconds", "/candidates[i]/seconds"}


def _files(root: Path) -> set[Path]:
    return {p.relative_to(root) for p in root.rglob("*") if p.is_file() and not SKIP & set(p.relative_to(root).parts)}


def _json_diff(x, y, path: str, out: set[str]) -> None:
    """The paths (list indices as [i]) where two JSON values differ (NaN equal to NaN)."""
    if isinstance(x, dict) and isinstance(y, dict):
        for k in set(x) | set(y):
            _json_diff(x.get(k), y.get(k), f"{path}/{k}", out)
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for u, v in zip(x, y):
            _json_diff(u, v, f"{path}[i]", out)
    elif x != y and not (isinstance(x, float) and isinstance(y, float) and np.isnan(x) and np.isnan(y)):
        out.add(path)


def _timing(key: str) -> bool:
    return key in TIMING or key.lstrip("/") in TIMING or key.startswith("/seconds_per_step/")


def compare(a: Path, b: Path) -> bool:
    """Print the differences of results trees a and b; True when only timing fields differ."""
    fa, fb = _files(a), _files(b)
    ok = fa == fb
    for rel in sorted(fa ^ fb, key=str):
        print(f"only in {'A' if rel in fa else 'B'}: {rel}")
    same = 0
    for rel in sorted(fa & fb, key=str):
        if (a / rel).read_bytes() == (b / rel).read_bytes():
            same += 1
            continue
        if rel.suffix == ".csv":
            x, y = pd.read_csv(a / rel), pd.read_csv(b / rel)
            keys = ({"(shape or columns)"} if list(x.columns) != list(y.columns) or len(x) != len(y)
                    else {c for c in x.columns if not x[c].equals(y[c])})
        elif rel.suffix == ".json":
            keys = set()
            _json_diff(json.loads((a / rel).read_text()), json.loads((b / rel).read_text()), "", keys)
        else:
            keys = {"(bytes)"}
        other = sorted(k for k in keys if not _timing(k))
        ok &= not other
        print(f"{rel}: timing {sorted(k for k in keys if _timing(k))}" + (f"; OTHER {other}" if other else ""))
    print(f"{same} files byte-identical; {'only timing fields differ' if ok else 'outputs DIFFER'}")
    return ok


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-1].strip())
    sys.exit(0 if compare(Path(sys.argv[1]), Path(sys.argv[2])) else 1)
