"""Benchmark: the steady-state envelope model against a time simulation of the same run.

Prints the time of one run's envelope (1000 drive frequencies) for 200 parameter sets
(target < 50 ms) and the ratio against simulating that run (700-2500 Hz at 300 Hz/s,
12.8 kHz, one parameter set) in the time domain, both measured here.
"""
import time

import numpy as np

from jointcal.models import G, IwanParams, MinistackModel, simulate, steady_state


def best_of(fn, n=5):
    times = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    m = 2.65 / G
    rng = np.random.default_rng(7)
    P, N = 200, 1000
    Fs = 313.0 * np.exp(rng.normal(0, 0.3, (P, 1)))
    KT = 1.02e6 * np.exp(rng.normal(0, 0.2, (P, 1)))
    chi = rng.uniform(-0.8, -0.4, (P, 1))
    batch = MinistackModel(m=m, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(Fs, KT, chi, 0.004))
    f = np.linspace(700, 2500, N)
    A = 5.0 * (1 + 0.01 * np.sin(f / 50))  # a measured base envelope with 1% ripple
    steady_state(batch, f, A)  # compile
    t_fast = best_of(lambda: steady_state(batch, f, A, direction="up"))
    one = MinistackModel(m=m, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(313.0, 1.02e6, -0.65, 0.004))
    fs, rate = 12800.0, 300.0
    T = (2500 - 700) / rate
    t = np.arange(int(fs * T)) / fs
    base = 5.0 * np.sin(2 * np.pi * (700 * t + 0.5 * rate * t**2))
    simulate(one, base[:1000], fs)  # compile
    t_sim = best_of(lambda: simulate(one, base, fs), n=3)
    t_one = best_of(lambda: steady_state(one, f, A))
    print(f"steady-state envelope, {P} parameter sets x {N} frequencies: {t_fast * 1e3:.1f} ms (target < 50 ms)")
    print(f"one parameter set: {t_one * 1e3:.2f} ms; time simulation of the same run ({T:.0f} s at 12.8 kHz): "
          f"{t_sim * 1e3:.1f} ms")
    print(f"ratio, time simulation / envelope model per parameter set: {t_sim / (t_fast / P):.0f}x")


if __name__ == "__main__":
    main()
