"""Acceptance: one backbone whatever the sweep, on force- and voltage-driven virtual rigs.

Run:  python tests/benchmarks/accept_backbone.py [--quick]

The jointed 100 Hz beam of `tests/_support/rigs.py` (a second, linear mode at 230 Hz at the driving
point; a small open-loop shaker with its electrical dynamics) at three drive levels, swept
at eta 0.5, 5, 50 and 500 (slow sweeps over +-30% of the mode; faster ones over 30-260 Hz,
the second mode included), up and down, with 2% noise, seeds 1-3, for both references.
Each run's read-out (q_in, f_res_hz, zeta_res) is set against the truth's curve at its own
q_in (the structure's first-harmonic balance for a force, the coupled rig's pole for a
voltage) and q_in against the amplitude the mode reached. Acceptance: every point within
0.1% in frequency and 5% in damping, and q_in within 3%. Printed: one row per run, then the
worst errors per reference and eta, and the modal stage's time per run.

--quick: one seed, up sweeps only.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).parents[2]))
from tests._support import rigs as _rigs  # noqa: E402

ETAS = (0.5, 5.0, 50.0, 500.0)


def main(quick: bool = False) -> pd.DataFrame:
    levels = _rigs.levels_V()
    seeds, directions = ((1,), ("up",)) if quick else ((1, 2, 3), ("up", "down"))
    parts = []
    with tempfile.TemporaryDirectory() as d:
        for ref in ("force", "voltage"):
            for eta in ETAS:
                for direction in directions:
                    for seed in seeds:
                        tag = f"{ref}_{eta:g}_{direction}_{seed}"
                        folder, truth = Path(d) / tag, Path(d) / f"{tag}.json"
                        _rigs.campaign(folder, truth, ref=ref, eta=eta, direction=direction, seed=seed, levels=levels)
                        t0 = time.perf_counter()
                        r = _rigs.read_out(folder, truth, ref)
                        r["seconds_per_run"] = (time.perf_counter() - t0) / len(r)
                        r["eta_set"], r["seed"] = eta, seed
                        parts.append(r)
                        for x in r.itertuples():
                            print(f"{ref:7s} eta {eta:5g} {direction:4s} seed {seed} {x.method:12s} eta {x.eta:7.2f} "
                                  f"q {x.q_in:.2e}: f {100 * x.f_err:+.3f}%  zeta {100 * x.zeta_err:+.2f}%  "
                                  f"q {100 * x.q_err:+.2f}% (envelope check {100 * x.q_peak_err:+.1f}%)  "
                                  f"[{x.flags}]", flush=True)
    t = pd.concat(parts, ignore_index=True)
    ok = (t["f_err"].abs() <= 1e-3) & (t["zeta_err"].abs() <= 0.05) & (t["q_err"].abs() <= 0.03)
    print("\nworst |error| per reference and eta (f %, zeta %, q_in %), runs passing:")
    for (ref, eta), g in t.groupby(["ref", "eta_set"]):
        print(f"{ref:7s} eta {eta:5g}: f {100 * g['f_err'].abs().max():.3f}  zeta {100 * g['zeta_err'].abs().max():.2f}  "
              f"q {100 * g['q_err'].abs().max():.2f}  pass {int(ok[g.index].sum())}/{len(g)}  "
              f"({g['seconds_per_run'].mean():.2f} s per run)")
    print(f"\nall: pass {int(ok.sum())}/{len(t)}")
    return t


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
