"""Test helpers (not jointcal code): measured envelopes of a known model with a known
effect, plus noise at the repeat scatter."""
import numpy as np

from jointcal.calibrate import CalibrateSettings
from jointcal.discrepancy.data import RunEnvelope
from jointcal.discrepancy.fit import Objective, candidate
from jointcal.models import G

M = 2.65 / G
TRUTH = np.array([280.0, 1.1e6, -0.6, 0.01, 7.0e5, 0.002])
SPACE = CalibrateSettings().space


def _runs(effect="baseline", values=(), noise=(0.05, 0.3), seed=0, rate=0.0):
    """Envelopes of the true model (+ effect) at 1, 3 and 10 g, up and down, with scatter noise."""
    rng = np.random.default_rng(seed)
    c = candidate(effect, SPACE, M)
    theta = np.r_[TRUTH, values]
    runs = []
    seq = 0
    for level in (1.0, 1.0, 3.0, 10.0):
        for direction in ("up", "down"):
            seq += 1
            f = np.linspace(1700, 2700, 80)
            row = dict(run_id=f"r{seq}", level_g=level, direction=direction, sequence=seq, f_res_hz=2200.0,
                       zeta_phase_resonance=0.02)
            probe = RunEnvelope(f, np.full(f.size, level), np.ones(f.size, complex), np.full(f.size, noise[0]),
                                np.full(f.size, noise[1]), rate if direction == "up" else -rate, row)
            T = Objective(c, [probe]).predict(theta, 0)
            T = T * 10 ** (rng.normal(0, noise[0], f.size) / 20) * np.exp(1j * np.radians(rng.normal(0, noise[1], f.size)))
            runs.append(RunEnvelope(f, probe.base_g, T, probe.sigma_db, probe.sigma_deg, probe.rate, row))
    return runs
