"""Benchmark: the envelopes stage against a bare ShortTimeFFT.stft on the same samples.

Run:  python tests/benchmarks/bench_envelopes.py
Target: the envelopes of a run (ridge tracking, demodulation of both
channels and the 2nd/3rd harmonics) take at most twice the time of one bare
`ShortTimeFFT.stft` of one channel with the same window and hop (ratio >= 0.5).
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.signal import ShortTimeFFT
from scipy.signal.windows import hann

from jointcal.io import read_manifest, read_run
from jointcal.measure.envelopes import envelopes, window_length

REPO = Path(__file__).resolve().parents[2]


def best(fn, n=7):
    t = np.inf
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def main():
    man = read_manifest(REPO / "raw_data" / "manifest.csv")
    ratios = []
    for row in man.to_dict("records")[:4]:
        df = read_run(REPO / "raw_data" / row["file"])
        fs = row["sample_rate_hz"]
        n = window_length(fs, row["sweep_rate_hz_per_s"], min(row["f_start_hz"], row["f_stop_hz"]))
        x = df["base_accel_g"].to_numpy()
        stft = ShortTimeFFT(hann(n, sym=False), n // 4, fs, scale_to="magnitude")
        t_bare = best(lambda: stft.stft(x))
        t_env = best(lambda: envelopes(df, row))
        ratios.append(t_bare / t_env)
        print(f"{row['run_id']}: {x.size} samples, window {n}: bare stft {t_bare * 1e3:.1f} ms, "
              f"envelopes {t_env * 1e3:.1f} ms, speed ratio {t_bare / t_env:.2f} (target >= 0.5)")
    print(f"median ratio {np.median(ratios):.2f}")


if __name__ == "__main__":
    main()
