"""Benchmark: what a workflow job costs before it computes anything (its interpreter and imports).

Run:  python tests/benchmarks/bench_job_startup.py [--repeat 3]

Snakemake runs each stage script (``workflow/scripts/<stage>.py``) in a new Python process, which imports the
package modules the script names before its first line of work. The example workflow runs 25 such jobs, and the
workflow tests of the suite run about a hundred. For each script this prints the CPU time (user + system, the
best of ``--repeat`` fresh processes) of importing what the script imports, beside two baselines measured in the
same run: a bare interpreter, and one importing numpy, pandas and matplotlib's Agg backend. It also says which heavy
third-party modules each import pulls in (scipy.optimize, scipy.signal, scipy.stats, numba, deap, matplotlib).

No target: a measurement to hold a restructure of the imports against (e.g. a package ``__init__`` that imports
its submodules only when a name is asked for). The kernels' first call from numba's cache (0.4 s a kernel on this
machine, 2026-11-27) comes on top and is not measured here.
"""
from __future__ import annotations

import argparse
import ast
import os
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCRIPTS = REPO / "workflow" / "scripts"
HEAVY = ("scipy.optimize", "scipy.signal", "scipy.stats", "numba", "deap", "matplotlib")
BASELINES = {"bare python": "pass", "numpy + pandas + matplotlib (Agg)":
             "import numpy, pandas, matplotlib; matplotlib.use('Agg'); import matplotlib.pyplot"}


def script_imports(script: Path) -> list[str]:
    """The ``jointcal`` modules a stage script imports (its import statements, in order)."""
    names = []
    for node in ast.walk(ast.parse(script.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("jointcal"):
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names += [a.name for a in node.names if a.name.startswith("jointcal")]
    return list(dict.fromkeys(names))


def cpu_of(code: str, repeat: int) -> tuple[float, list[str]]:
    """Best CPU time (s) over `repeat` fresh interpreters running `code`, and the HEAVY modules it loaded."""
    probe = (f"{code}\nimport sys, resource\nr = resource.getrusage(resource.RUSAGE_SELF)\n"
             f"print(r.ru_utime + r.ru_stime, ','.join(m for m in {HEAVY!r} if m in sys.modules))")
    env = {**os.environ, "PYTHONPATH": str(REPO / "src"), "MPLBACKEND": "Agg"}
    best, heavy = float("inf"), []
    for _ in range(repeat):
        out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env, check=True,
                             cwd=REPO).stdout.split()
        if float(out[0]) < best:
            best, heavy = float(out[0]), (out[1].split(",") if len(out) > 1 else [])
    return best, heavy


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    base = {name: cpu_of(code, args.repeat)[0] for name, code in BASELINES.items()}
    for name, s in base.items():
        print(f"baseline {name}: {s:.2f} s of CPU")
    ref = base["numpy + pandas + matplotlib (Agg)"]
    total = 0.0
    print(f"\n{'script':24s} {'CPU s':>6s} {'x base':>7s}  heavy modules loaded")
    for script in sorted(SCRIPTS.glob("*.py")):
        mods = script_imports(script)
        s, heavy = cpu_of("\n".join(f"import {m}" for m in mods), args.repeat)
        total += s
        print(f"{script.name:24s} {s:6.2f} {s / ref:7.2f}  {', '.join(heavy) or '-'}"
              f"  ({', '.join(re.sub('^jointcal.', '', m) for m in mods)})")
    print(f"\nsum over the {len(list(SCRIPTS.glob('*.py')))} scripts: {total:.1f} s of CPU (one job each)")


if __name__ == "__main__":
    main()
