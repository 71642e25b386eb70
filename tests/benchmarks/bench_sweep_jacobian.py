"""Benchmark: the sweep fit's Jacobian, forward sensitivities against forward differences, in one run.

Run:  python tests/benchmarks/bench_sweep_jacobian.py [--blas-threads N] [--repeats K]

The force- and voltage-driven jointed-beam rigs of `accept_backbone.py --quick` (`tests/_support/rigs.py`: three
levels, up sweeps, seed 1, 2% noise) at eta 0.5 and 5. Each run is read by the modal stage
(`jointcal.measure.modal.measure_run`) twice in turn, with the sweep fit's Jacobian by forward
differences (`jacobian='2-point'`, the baseline: the scheme before) and by forward sensitivities
(the default), each K times (the fastest kept: the machine is shared). Printed per reference and
eta: seconds per run of the sweep fit alone and of the whole modal stage, before and after, their
ratio, and the largest change of the read-out (f, zeta, q_in) between the two; then both read-outs'
errors against the truth's curve.

BLAS threads: 1 unless --blas-threads says otherwise, as Snakemake sets them for the modal rule (no
`threads:`, so 1). With two OpenBLAS threads on a loaded 2-core machine the least squares' SVD of
the Jacobian alone took 60-120 ms a call.
"""
from __future__ import annotations

import os
import sys

_THREADS = sys.argv[sys.argv.index("--blas-threads") + 1] if "--blas-threads" in sys.argv else "1"
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = _THREADS  # before numpy is imported

import json  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import pandas as pd  # noqa: E402

import jointcal.measure._excited as excited  # noqa: E402
from jointcal.io import read_manifest, read_run  # noqa: E402
from jointcal.measure.modal import measure_run  # noqa: E402
from jointcal.measure.sweepfit import fit_swept_mode  # noqa: E402

sys.path.insert(0, str(Path(__file__).parents[2]))
from tests._support import rigs as _rigs  # noqa: E402

SCHEMES = ("2-point", "sensitivity")


def _read(record, row, scheme: str) -> tuple[dict, float, float]:
    """The modal stage's read-out of one run with the sweep fit's Jacobian by `scheme`, and the seconds of
    the sweep fit alone and of the whole stage."""
    spent = []

    def timed(*args, **kw):
        t0 = time.perf_counter()
        out = fit_swept_mode(*args, **kw, jacobian=scheme)
        spent.append(time.perf_counter() - t0)
        return out

    excited.fit_swept_mode = timed
    try:
        t0 = time.perf_counter()
        props = measure_run(record, row)[2]
        return props, sum(spent), time.perf_counter() - t0
    finally:
        excited.fit_swept_mode = fit_swept_mode


def main(repeats: int = 1) -> pd.DataFrame:
    levels = _rigs.levels_V()
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for ref in ("force", "voltage"):
            for eta in (0.5, 5.0):
                folder, truth = Path(d) / f"{ref}_{eta:g}", Path(d) / f"{ref}_{eta:g}.json"
                _rigs.campaign(folder, truth, ref=ref, eta=eta, direction="up", seed=1, levels=levels)
                runs = {r["run_id"]: r for r in json.loads(truth.read_text())["runs"]}
                for _, row in read_manifest(folder / "manifest.csv").iterrows():
                    row = row.to_dict()
                    record = read_run(folder / row["file"])
                    _read(record, row, "sensitivity")  # numba's compile or cache load outside the timing
                    out = dict(ref=ref, eta=eta, run_id=row["run_id"])
                    best = {s: (None, float("inf"), float("inf")) for s in SCHEMES}
                    for _ in range(repeats):
                        for scheme in SCHEMES:  # in turn: a change of the machine's load hits both
                            props, fit_s, stage_s = _read(record, row, scheme)
                            if stage_s < best[scheme][2]:
                                best[scheme] = (props, fit_s, stage_s)
                    q_t = runs[row["run_id"]]["q_peak_in" if ref == "force" else "q_rig_peak_in"]
                    for scheme, (props, fit_s, stage_s) in best.items():
                        f_t, z_t = _rigs.truth_curve(ref, props["q_in"])
                        out |= {f"fit_s_{scheme}": fit_s, f"stage_s_{scheme}": stage_s,
                                f"f_{scheme}": props["f_res_hz"], f"zeta_{scheme}": props["zeta_res"],
                                f"q_{scheme}": props["q_in"], f"method_{scheme}": props["f_res_method"],
                                f"f_err_{scheme}": props["f_res_hz"] / f_t - 1,
                                f"zeta_err_{scheme}": props["zeta_res"] / z_t - 1,
                                f"q_err_{scheme}": props["q_in"] / q_t - 1}
                    rows.append(out)
                    print(f"{ref:7s} eta {eta:3g} {row['run_id']}: sweep fit {out['fit_s_2-point']:.2f} -> "
                          f"{out['fit_s_sensitivity']:.2f} s, stage {out['stage_s_2-point']:.2f} -> "
                          f"{out['stage_s_sensitivity']:.2f} s; methods {out['method_2-point']}/"
                          f"{out['method_sensitivity']}", flush=True)
    t = pd.DataFrame(rows)
    for k in ("f", "zeta", "q"):
        t[f"d{k}"] = t[f"{k}_sensitivity"] / t[f"{k}_2-point"] - 1
    print(f"\nBLAS threads {_THREADS}; fastest of {repeats}; seconds per run, forward differences (before) -> "
          "forward sensitivities (after), ratio; largest read-out change after/before - 1:")
    for (ref, eta), g in t.groupby(["ref", "eta"]):
        fb, fa, sb, sa = (g[c].mean() for c in ("fit_s_2-point", "fit_s_sensitivity", "stage_s_2-point",
                                                "stage_s_sensitivity"))
        print(f"{ref:7s} eta {eta:3g}: sweep fit {fb:5.2f} -> {fa:5.2f} s ({fb / fa:4.1f}x); modal stage {sb:5.2f} "
              f"-> {sa:5.2f} s ({sb / sa:4.1f}x); |df| {100 * g['df'].abs().max():.2e}%  |dzeta| "
              f"{100 * g['dzeta'].abs().max():.2e}%  |dq_in| {100 * g['dq'].abs().max():.2e}%")
    print("\nerrors against the truth's curve at each run's q_in (worst |f| %, |zeta| %, |q_in| %), before / after:")
    for (ref, eta), g in t.groupby(["ref", "eta"]):
        worst = [f"{100 * g[f'{k}_err_{s}'].abs().max():.3f}" for s in SCHEMES for k in ("f", "zeta", "q")]
        print(f"{ref:7s} eta {eta:3g}: {' '.join(worst[:3])} / {' '.join(worst[3:])}")
    return t


if __name__ == "__main__":
    main(repeats=int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 1)
