"""Benchmark: the swept-sine simulator (exact Iwan) against slider-based integrators.

Run:  python tests/benchmarks/bench_simulator.py
Prints wall times, accuracy against a converged reference, and ratios measured in
this one run (targets: >= 10x vs the same integrator with a
100-slider Iwan, >= 1000x vs scipy solve_ivp with sliders, >= 500 simulated seconds
per wall second for one sweep).
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from jointcal.models import G, IwanParams, MinistackModel, simulate
from jointcal.models.sliders import slider_set

M = 2.65 / G
MODEL = MinistackModel(m=M, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(313, 1.02e6, -0.65, 0.004))
FS = 25600.0


def sweep(fa, fb, rate, level, fs=FS):
    t = np.arange(int(fs * abs(fb - fa) / rate)) / fs
    return t, level * np.sin(2 * np.pi * (fa * t + 0.5 * np.sign(fb - fa) * rate * t**2))


def best_of(fn, n=3):
    best = np.inf
    out = None
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def rel_err(y, ref):
    return float(np.max(np.abs(y - ref)) / np.max(np.abs(ref)))


def envelope_peak(y, fs):
    """Peak of the response envelope (1-cycle RMS * sqrt 2), a proxy for resonance amplitude."""
    n = int(fs / 2000)
    return float(np.sqrt(2 * np.convolve(y**2, np.ones(n) / n, "same")).max())


def solve_ivp_sliders(t, a, k_sl, phi_sl, rtol=1e-6):
    """Reference-style code: slider anchors as ODE states (eq. 3.2), RK45."""
    spline = CubicSpline(t, a * G)
    k_lin = MODEL.k
    kt = k_sl.sum()
    c = 2 * MODEL.zeta_v * np.sqrt((MODEL.k + kt) * M)

    def rhs(_t, s):
        z, v, x = s[0], s[1], s[2:]
        dev = z - x
        slipping = (np.abs(dev) >= phi_sl) & (v * dev > 0)
        F = np.dot(k_sl, np.clip(dev, -phi_sl, phi_sl))
        acc = -spline(_t) - (k_lin * z + c * v + F) / M
        return np.concatenate(([v, acc], np.where(slipping, v, 0.0)))

    sol = solve_ivp(rhs, (t[0], t[-1]), np.zeros(2 + k_sl.size), t_eval=t, rtol=rtol, atol=1e-12, method="RK45")
    z, v, x = sol.y[0], sol.y[1], sol.y[2:]
    F = np.sum(k_sl[:, None] * np.clip(z - x, -phi_sl[:, None], phi_sl[:, None]), axis=0)
    return (-(k_lin * z + c * v + F) / M) / G  # absolute slug acceleration, g


def main():
    print("== one sweep: Table 3.2 joint, 5 g, 700 -> 2500 Hz at 100 Hz/s, fs = 25.6 kHz")
    t, a = sweep(700, 2500, 100, 5.0)
    simulate(MODEL, a[:2000], FS)  # compile
    T = t[-1]
    wall, res = best_of(lambda: simulate(MODEL, a, FS))
    ref = simulate(MODEL, a, FS, n_sub=16).response_g
    print(f"exact Iwan, n_sub={res.n_sub}: {wall:.3f} s wall for {T:.1f} s simulated "
          f"= {T / wall:.0f} simulated s per wall s (target >= 500); "
          f"error vs n_sub=16: {rel_err(res.response_g, ref):.2e}, "
          f"envelope peak {envelope_peak(res.response_g, FS) / envelope_peak(ref, FS) - 1:+.2e}")

    print("== (a) same integrator, slider Iwan")
    k100, p100 = slider_set(MODEL.iwan, 100, scheme="uniform")
    simulate(MODEL, a[:2000], FS, sliders=(k100, p100))
    wall_a, ya = best_of(lambda: simulate(MODEL, a, FS, sliders=(k100, p100)))
    print(f"100 uniform sliders (tmdsimpy's scheme): {wall_a:.3f} s wall, error {rel_err(ya.response_g, ref):.2e}, "
          f"envelope peak {envelope_peak(ya.response_g, FS) / envelope_peak(ref, FS) - 1:+.2e}; "
          f"exact is {wall_a / wall:.1f}x faster (target >= 10x)")
    for n in (1000, 10000):
        ks, ps = slider_set(MODEL.iwan, n)
        w, ys = best_of(lambda: simulate(MODEL, a, FS, sliders=(ks, ps)), n=1)
        print(f"{n} equal-stiffness sliders: {w:.3f} s wall, error {rel_err(ys.response_g, ref):.2e}; "
              f"exact is {w / wall:.0f}x faster")

    print("== (b) scipy solve_ivp (RK45) with 100 sliders as ODE states, on a 0.1 s window at resonance")
    i0 = int((2000 - 700) / 100 * FS)
    sl = slice(i0, i0 + int(0.1 * FS))
    # the window starts from rest in both codes, so they solve the same problem
    wall_b, yb = best_of(lambda: solve_ivp_sliders(t[sl] - t[sl][0], a[sl], k100, p100), n=1)
    ref_w = simulate(MODEL, a[sl], FS, n_sub=16).response_g
    wall_w, yw = best_of(lambda: simulate(MODEL, a[sl], FS), n=5)
    print(f"solve_ivp: {wall_b:.2f} s wall for 0.1 s simulated, error {rel_err(yb, ref_w):.2e}; "
          f"jointcal: {wall_w * 1e3:.2f} ms, error {rel_err(yw.response_g, ref_w):.2e}; "
          f"ratio {wall_b / wall_w:.0f}x on the window, {wall_b / 0.1 / (wall / T):.0f}x per simulated second "
          f"(target >= 1000x)")


if __name__ == "__main__":
    main()
