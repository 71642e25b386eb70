"""Opt-in benchmark: the real beam's dwell ring-downs against its chirps' sweep-fit backbone (one structure,
one backbone).

Run:  python tests/benchmarks/bench_real_ringdown.py

Reads the five Test.Lab exports of `../shared/real/unesp-bert-dwell-mode1/` as the lab hands them over
(`jointcal.io` reads Test.Lab's MKS storage: the accelerometer in m/s^2), takes Acc1 (beside the laser at the
tip) in g, and reads each free decay after the dwell with `jointcal.measure.ringdown.ringdown_backbone`
(the decay's start from the response: these exports hold no drive channel). The six chirps of
`../shared/real/unesp-bert-mode1/` are read by the modal stage's own functions (`measure_run`). Printed: each
ring-down's span, and per chirp the ring-down windows within 30% of its q_in: their median frequency and
damping beside the chirp's, and the difference. Skips, saying why, when the records are absent.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

REAL = Path(__file__).resolve().parents[2].parent / "shared" / "real"


def main() -> int:
    dwell, chirps = REAL / "unesp-bert-dwell-mode1", REAL / "unesp-bert-mode1"
    if not (dwell.is_dir() and (chirps / "manifest.csv").is_file()):
        print(f"skipped: the real records are not at {REAL} (they are not part of the repository)")
        return 0
    from jointcal.io import read_manifest, read_run
    from jointcal.io._lab_channels import lab_channels
    from jointcal.measure.modal import measure_run
    from jointcal.measure.ringdown import ringdown_backbone
    from jointcal.units import G_SI

    parts = []
    for f in (16, 17, 18, 19, 20):
        ch = {c.names[0]: c for c in lab_channels(dwell / f"Sine_{f}Hz_Time.mat", "Test.Lab MAT")}
        acc = ch["Time Acc1:+X"]
        bb = ringdown_backbone(acc.values / G_SI, 1.0 / acc.dt, 18.5).assign(dwell_hz=f)
        print(f"dwell {f} Hz: {len(bb)} windows, q {bb['q_in'].max():.3g} to {bb['q_in'].min():.3g} in "
              f"({np.log10(bb['q_in'].max() / bb['q_in'].min()):.2f} decades), f {bb['f_hz'].min():.4f}-"
              f"{bb['f_hz'].max():.4f} Hz, zeta {bb['zeta'].min():.4f}-{bb['zeta'].max():.4f}")
        parts.append(bb)
    rd = pd.concat(parts, ignore_index=True)
    print("\nchirp (sweep fit)                      | ring-down windows within 30% of its q_in")
    for _, row in read_manifest(chirps / "manifest.csv").iterrows():
        row = row.to_dict()
        p = measure_run(read_run(chirps / row["file"], row), row)[2]
        near = rd[(rd["q_in"] > p["q_in"] / 1.3) & (rd["q_in"] < p["q_in"] * 1.3)]
        line = f"{row['run_id']}: q {p['q_in']:.3f} f {p['f_res_hz']:.4f} zeta {p['zeta_res']:.4f} | "
        if len(near):
            f_rd, z_rd = near["f_hz"].median(), near["zeta"].median()
            line += (f"n {len(near):2d} f {f_rd:.4f} zeta {z_rd:.4f}: df {100 * (f_rd / p['f_res_hz'] - 1):+.3f}%, "
                     f"dzeta {100 * (z_rd / p['zeta_res'] - 1):+.1f}%")
        else:
            line += "no ring-down window at this amplitude"
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
