"""The dwell read-out (jointcal.measure.dwell) against closed forms: a linear mode's FRF, and the exact Iwan
simulator's steady states held against the joint's first-harmonic balance at the amplitude reached."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.measure.dwell import dwell_mode, dwell_point
from jointcal.models import IwanParams, MinistackModel, harmonic_balance, simulate
from jointcal.units import G
from tests._support.kinds_records import FN, ZETA, linear_dwell, linear_frf

JOINT = dict(k=818.0, Fs=4.0, KT=204.0, chi=-0.5, beta=0.1, zeta_v=0.008, m=1.0 / G)  # a 100 Hz jointed beam


def test_a_linear_modes_dwells_give_its_frf_resonance_and_damping():
    fs, rng = 1024.0, np.random.default_rng(3)
    pts = []
    for f in (19.3, 19.8, 20.1, 20.4, 20.8, 21.3):
        rec = linear_dwell(fs, f, 0.5, 12.0, 3.0, noise=0.01, rng=rng)  # 0.1-0.3% of the response's amplitude
        p = dwell_point(rec["response_accel_g"].to_numpy(), rec["drive_V"].to_numpy(), fs, f)
        assert abs(p["ratio"] / linear_frf(f) - 1) < 1e-3 and p["flags"] == []
        assert abs(p["ref_amp"] - 0.5) < 1e-6 and 0 <= 12.0 - p["t1_s"] < 1 / f  # read up to the last peak
        pts.append(p)
    m = dwell_mode([p["f_hz"] for p in pts], [p["X"] for p in pts], [p["q_in"] for p in pts])
    assert abs(m["f_hz"] / FN - 1) < 5e-4 and abs(m["zeta"] / ZETA - 1) < 0.02 and m["flags"] == []
    for q, f_n, z in m["points"]:  # a linear mode: every point its natural frequency and damping
        assert abs(f_n / FN - 1) < 5e-4 and abs(z / ZETA - 1) < 0.02


def test_a_dwell_whose_transient_has_not_died_out_is_flagged():
    fs = 1024.0
    short = linear_dwell(fs, 20.1, 0.5, 2.0, 3.0)  # 2 s: the transient decays by exp(-zeta wn 1 s) = 8% only
    p = dwell_point(short["response_accel_g"].to_numpy(), short["drive_V"].to_numpy(), fs, 20.1)
    assert p["flags"] == ["dwell_transient"] and p["change"] > 0.01
    long = linear_dwell(fs, 20.1, 0.5, 12.0, 3.0)
    assert dwell_point(long["response_accel_g"].to_numpy(), long["drive_V"].to_numpy(), fs, 20.1)["flags"] == []


def test_dwells_on_one_side_of_resonance_say_so():
    pts = [(f, -linear_frf(f) * G / (2 * np.pi * f) ** 2, 1.0) for f in (18.0, 18.5, 19.0)]  # in per V
    m = dwell_mode(*map(np.array, zip(*pts)))
    assert "no_quadrature" in m["flags"] and abs(m["f_hz"] / FN - 1) < 1e-6  # the nearest point's own wn


@pytest.fixture(scope="module")
def iwan_dwells():
    """Force dwells at 0.3 lbf across the jointed beam's phase resonance (97.2 Hz there), 3 s each."""
    fs = 2048.0
    t = np.arange(int(3.0 * fs)) / fs
    model = MinistackModel(m=JOINT["m"], k=JOINT["k"], zeta_v=JOINT["zeta_v"],
                           iwan=IwanParams(JOINT["Fs"], JOINT["KT"], JOINT["chi"], JOINT["beta"]))
    pts = []
    for f in (96.6, 97.0, 97.4, 97.8, 98.2):
        force = 0.3 * np.clip(t / 0.2, 0, 1) * np.sin(2 * np.pi * f * t)
        base_g = -force / (JOINT["m"] * G)  # a fixed-base oscillator driven by the force
        acc = simulate(model, base_g, fs).response_g - base_g
        acc += 1e-3 * np.std(acc) * np.random.default_rng(int(f * 10)).standard_normal(acc.size)
        pts.append(dwell_point(acc, force, fs, f))
    return pts


def test_the_exact_iwan_dwells_read_the_harmonic_balance_at_the_amplitude_reached(iwan_dwells):
    pts = iwan_dwells
    assert all(p["flags"] == [] for p in pts)
    m = dwell_mode([p["f_hz"] for p in pts], [p["X"] for p in pts], [p["q_in"] for p in pts])
    joint = (JOINT["Fs"], JOINT["KT"], JOINT["chi"], JOINT["beta"], JOINT["k"], JOINT["m"], JOINT["zeta_v"])
    f_t, z_t = harmonic_balance(np.array([m["q_in"]]), *joint)
    assert m["flags"] == [] and 96.6 < m["f_hz"] < 98.2
    assert abs(m["f_hz"] / f_t[0] - 1) < 5e-4 and abs(m["zeta"] / z_t[0] - 1) < 0.02  # the 0.05% / 2%
    assert abs(abs(m["A"]) * JOINT["m"] - 1) < 0.01  # the modal constant of a force on a mass: 1/m
    q = np.array([p[0] for p in m["points"]])
    f_p, z_p = harmonic_balance(q, *joint)
    assert np.abs(np.array([p[1] for p in m["points"]]) / f_p - 1).max() < 5e-4
    # the joint is nonlinear here: the points' amplitudes and frequencies differ beyond the tolerance
    assert q.max() / q.min() > 1.1 and f_p.max() / f_p.min() - 1 > 5e-4
