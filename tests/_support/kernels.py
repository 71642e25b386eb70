"""Test helpers (not jointcal code): the measure package's numba kernels compiled into numba's cache once.

`jointcal.models.kernels.compile_kernels` compiles the models' kernels (the workflow's `compile_kernels` rule and
tests/conftest.py call it). The measure package has its own (``cache=True`` too): `_decay_window` (ring-down and
forced-decay windows), `_rotating` and `_rotating_sensitivity` (the swept-mode fit of force- and voltage-driven runs)
and `_coil` (that fit with the shaker's coil). On a fresh clone each process that calls one before another has
written the cache compiles it (measured cold, one process each: `_coil` about 21 s of CPU, the other three about
28 s); an xdist worker, or a Snakemake job started by a test, that calls one while another is still compiling it
compiles it again. `compile_measure_kernels` calls each through the functions the package calls it from, with the
argument types it passes, on small inputs (a linear mode), so that the suite compiles each once, at its start.
"""
from __future__ import annotations

import time


def compile_measure_kernels() -> float:
    """Call every kernel of jointcal.measure once (compiling it, or loading it from numba's cache); the seconds."""
    from dataclasses import replace

    import numpy as np

    from jointcal.measure._rotating import demodulate, passage
    from jointcal.measure._sweep_problem import NP, Problem
    from jointcal.measure.ringdown import ringdown_backbone
    from jointcal.measure.sweepfit import fit_swept_mode
    from jointcal.synth.daq import controlled_sweep
    from jointcal.units import G
    from tests._support.lti import lsim

    start = time.perf_counter()
    rng = np.random.default_rng(0)
    # _decay_window: a linear ring-down read window by window (tests/measure/test_ringdown.py's first case, shorter)
    fs, f0, z0, t_cut = 1024.0, 18.6, 0.005, 1.0
    t = np.arange(int(8 * fs)) / fs
    wn = 2 * np.pi * f0
    x = np.where(t < t_cut, np.cos(wn * t), np.exp(-z0 * wn * (t - t_cut)) * np.cos(wn * t))
    ringdown_backbone(x + 1e-4 * rng.standard_normal(t.size), fs, 18.0, start=int(t_cut * fs))
    # _rotating, _rotating_sensitivity: the swept-mode fit of a linear 100 Hz mode under a force chirp (its response
    # by `lsim`, not the models' integrator: that kernel is compile_kernels', compiled beside this at the same time)
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    k, c = m * (2 * np.pi * f0) ** 2, 2 * zeta * m * 2 * np.pi * f0
    _, _, F = controlled_sweep(1024.0, 70.0, 130.0, 5 * (f0 * zeta) ** 2, 1.0, rng=rng, ramp_s=0.01, tail_s=0.3,
                               ripple=0.0, distortion=(0.0, 0.0))
    acc = lsim(([[0.0, 1.0], [-k / m, -c / m]], [[0.0], [1.0 / m]], [[-k / (m * G), -c / (m * G)]], [[1.0 / (m * G)]]),
               F, np.arange(F.size) / 1024.0)
    acc = acc + 0.003 * acc.std() * rng.standard_normal(acc.size)
    fit_swept_mode(F, acc, 1024.0, 1.03 * f0, 2 * zeta, modal_phase=0.0)
    # _coil: the same fit's problem with a coil, its misfit and Jacobian (tests/measure/test_coil.py's way in)
    cut = int(np.argmax(np.abs(acc))) - int(0.2 * 1024)
    sig = demodulate(F[cut:], acc[cut:], 1024.0, f0, zeta, 0.45, 6.0)
    w0 = 2 * np.pi * f0
    for free_start in (True, False):
        prob = Problem.build(passage(sig, 0.15, 0.02, 6.0, free_start), f0, zeta, 0.15, None, 0.01, 0.3, 0.3)
        prob = replace(prob, l_lo=-40.0, l_hi=5.0).with_coil((0.7 * w0, 0.02 * w0**2), True)
        free = prob.free_all
        p = np.zeros(NP)
        prob.misfit(p[free], free)
        prob.jacobian_matrix(p[free], free)
    return time.perf_counter() - start
