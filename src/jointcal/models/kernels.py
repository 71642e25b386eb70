"""Compile the numba kernels once, before the stages that call them run side by side.

The kernels (`_envelope_kernel`, `_integrator`, `_masing`, `_amplitude_kernel`) are compiled on first call and
cached by numba next to their source (``cache=True``). On a fresh install the cache is
empty, and every process that calls a kernel before another has written it compiles it
again: on the example campaign that was about 35 s of one discrepancy job's 72 s. `compile_kernels` calls each kernel
through the same public functions the stages call, with the same argument types, on a
small model, so one process writes the cache and the others load it.
"""
from __future__ import annotations

import time

import numpy as np

from ..units import G
from .amplitude import harmonic_balance
from .elements import cubic_spring, quadratic_damper
from .envelope import steady_state
from .iwan import IwanParams
from .simulate import simulate
from .structure import Fixture, MinistackModel
from .swept import SweepDrive, quasi_steady, quasi_steady_runs
from .swept_integrated import swept_transmissibility

__all__ = ["compile_kernels"]


def _models() -> list[MinistackModel]:
    """One parameter set and a batch, rigid and on the fixture, with and without extra elements."""
    m, iwan = 2.65 / G, IwanParams(313.0, 1.02e6, -0.65, 0.004)
    batch = IwanParams(np.array([[313.0], [200.0]]), 1.02e6, -0.65, 0.004)
    fixture = Fixture(4 * m, 5500.0, 0.01)
    elements = (cubic_spring(1e9), quadratic_damper(1.0))
    return [MinistackModel(m=m, k=6.12e5, zeta_v=0.0015, iwan=iwan),
            MinistackModel(m=m, k=6.12e5, zeta_v=0.0015, iwan=iwan, fixture=fixture, elements=elements),
            MinistackModel(m=m, k=np.array([[6.12e5], [5e5]]), zeta_v=0.0015, iwan=batch),
            MinistackModel(m=m, k=np.full((64, 1), 6.12e5), zeta_v=0.0015, iwan=iwan)]  # the threaded solver


def compile_kernels() -> float:
    """Call every kernel once (compiling it, or loading it from numba's cache); returns the seconds taken."""
    start = time.perf_counter()
    f = np.linspace(1800.0, 2600.0, 40)
    t = np.linspace(0.0, 2.0, 40)
    drive = SweepDrive(t, f, np.full(40, 2.0), 0.02)
    harmonic_balance(np.geomspace(1e-6, 1e-3, 4), np.array([[313.0], [200.0]]), 1.02e6, -0.65, 0.004, 6.12e5,
                     2.65 / G, 0.0015)  # the GA's and the posterior's amplitude curves
    for model in _models():
        for direction in ("up", "down"):
            steady_state(model, f, 2.0, direction=direction)
            quasi_steady(model, f, 2.0, rate_hz_per_s=400.0, direction=direction)
        quasi_steady_runs(model, [(f, np.full(40, 2.0), 400.0, np.zeros(40), "up")])
        if np.ndim(model.k) == 0:
            swept_transmissibility(model, drive, t[5:-5], f_res_hz=2200.0, zeta=0.01)
            fs = 10240.0
            tt = np.arange(int(0.05 * fs)) / fs
            simulate(model, 2.0 * np.sin(2 * np.pi * (1800.0 + 2000.0 * tt) * tt), fs)
    return time.perf_counter() - start
