"""A voltage drive's slope refit (jointcal.discrepancy.drive.refine_slope) on known truths.

Measured envelopes of the jointed beam (tests/_support/beam_runs.py's mode, its Iwan joint at the truth) driven through
a known modal constant A(w), with noise at the repeat scatter (0.05 dB, 0.3 deg); the read-out's drive is the truth's
A_c at w_c with no slope (the read-out's ridge holds it near zero), and the slope is refit.

Oracles: a coil's 1 / (1 + i w tau) has the relative slope A' w_c / A_c = d ln A / d ln w = -i x / (1 + i x) at
w_c, x = w_c tau, of magnitude x / sqrt(1 + x^2) < 1 at any corner; a drive linear in w has the slope it was given.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from jointcal.discrepancy import drive
from jointcal.discrepancy.data import RunEnvelope
from jointcal.discrepancy.drive import refine_slope
from jointcal.discrepancy.fit import Objective, candidate
from jointcal.models import G
from jointcal.validate.drive import gain_at
from tests._support.beam_runs import BEAM, BEAM_JOINT, GAINS, beam_space

C0 = candidate("baseline", beam_space(), BEAM.m)
WC = 2 * np.pi * BEAM.f0_hz  # rad/s
AC = GAINS["voltage"][0]  # the modal constant at w_c, (in/s^2)/V: tests/_support/beam_runs.py's amplifier's
LEVELS_V = (0.05, 0.15, 0.45)  # equivalent base 0.04-0.4 g: the joint softens across them
COIL_BOUND = 1.0  # sup over x of x / sqrt(1 + x^2)


def _frames(modal_constant, gain=None) -> list[RunEnvelope]:
    """The campaign's frames (0.7-1.3 f0, up and down at each level) driven through modal_constant(f_hz) -> A (complex,
    (in/s^2)/V): equivalent base -A / G and base amplitude |A| V / G, as `run_envelope` sets them, the rows carrying
    the drive's `gain` as the stage's do; T not yet measured."""
    runs = []
    f = np.linspace(0.7, 1.3, 40) * BEAM.f0_hz
    eq = -modal_constant(f) / G
    for level in LEVELS_V:
        for direction, rate in (("up", 4.0), ("down", -4.0)):
            row = dict(run_id=f"r{len(runs) + 1}", level_V=level, direction=direction, sequence=len(runs) + 1,
                       f_res_hz=BEAM.f0_hz, zeta_res=0.01, drive_gain=gain)
            runs.append(RunEnvelope(f, level * np.abs(eq), np.ones(f.size, complex), np.full(f.size, 0.05),
                                    np.full(f.size, 0.3), rate, row, level=level, equivalent_base=eq))
    return runs


def _campaign(true_constant, seed: int = 0):
    """`refine_slope`'s `build` for a campaign measured through the true modal constant (noise at the scatter): each
    drive's frames with the measured T."""
    rng = np.random.default_rng(seed)
    truth = Objective(C0, _frames(true_constant))
    T = [truth.predict(BEAM_JOINT, i) * 10 ** (rng.normal(0, 0.05, r.f_hz.size) / 20)
         * np.exp(1j * np.radians(rng.normal(0, 0.3, r.f_hz.size))) for i, r in enumerate(truth.runs)]

    def build(gain):
        return [replace(r, T=t) for r, t in zip(_frames(lambda f: gain_at(gain, f), gain), T)]
    return build


def _relative(gain) -> complex:
    return complex(gain[1] * gain[2] / gain[0])  # A' w_c / A_c


READ_OUT = (AC, 0j, WC)  # the read-out's drive: the truth's A_c, no slope


@pytest.mark.parametrize("x", [0.094, 1.0, 3.0])  # w_c tau: the beam rig's coil (L/R 0.15 ms at 100 Hz), 1, 3
def test_a_coils_slope_is_refit_and_kept(x):
    """Envelopes driven through a coil A_0 / (1 + i w tau) (exact, not linearised): the refit relative slope is the
    coil's, -i x / (1 + i x), within 10% of its magnitude (the fit is a chord of the curve over 0.7-1.3 w_c), inside
    the bound, and kept: the gain and runs returned carry it, and the baseline's fast-model E falls."""
    tau = x / WC
    a0 = AC * (1 + 1j * x)  # so that A(w_c) = AC
    build = _campaign(lambda f: a0 / (1 + 1j * 2 * np.pi * f * tau))
    gain, runs, info = refine_slope(C0, BEAM_JOINT, READ_OUT, build, max_nfev=20)
    coil = -1j * x / (1 + 1j * x)
    assert abs(coil) == pytest.approx(x / np.sqrt(1 + x**2)) and abs(coil) < COIL_BOUND
    got = _relative(gain)
    print(f"x {x}: coil {coil:.4f}, refit {got:.4f}; E {info['baseline_E_read_out']:.2f} -> "
          f"{info['baseline_E_refined']:.2f}")
    assert abs(got - coil) <= 0.1 * abs(coil)
    assert gain[0] == AC and gain[2] == WC  # A_c and w_c kept (the read-out's resonance fixes them)
    assert complex(*info["relative_slope_refined"]) == pytest.approx(got)
    assert info["baseline_E_refined"] < info["baseline_E_read_out"]
    f = runs[0].f_hz
    assert np.allclose(runs[0].equivalent_base, -gain_at(gain, f) / G)


def test_a_channel_delay_is_not_taken_into_the_coil():
    """Envelopes driven through the rig's coil (x = 0.094) with the response channel delayed by tau (w_c tau = 0.25),
    A_c holding the delay's phase at w_c as the read-out's does. The coil ties its phase slope to its magnitude tilt,
    so it cannot take the delay's slope, -i w_c tau, which is all phase: refit with the baseline, the coil's x lands
    between the truth's and the 0.40 the whole phase slope would ask, its magnitude tilt then off the data, and E stays
    above twice the scatter. Refit with the library's channel_delay (from its fit on the read-out's drive, as the
    stage scores it), E is at the scatter (< 1.3) and the coil no larger than its tilt allows (x < 0.15). A coil this
    small tilts the magnitude by x^2 (0.9%), under the noise, and lags like a delay of L / R: the data fix the sum of
    the two lags, tau + L / R, which the fit finds within 5%. A free complex slope would have taken the delay
    (-0.009-0.34i here), leaving channel_delay nothing to explain."""
    x0, theta = 0.094, 0.25
    tau_l, tau = x0 / WC, theta / WC
    a0 = AC * (1 + 1j * x0)
    build = _campaign(lambda f: a0 / (1 + 1j * 2 * np.pi * f * tau_l) * np.exp(-1j * (2 * np.pi * f - WC) * tau))
    _, _, base = refine_slope(C0, BEAM_JOINT, READ_OUT, build, max_nfev=20)
    whole = (1 - np.sqrt(1 - 4 * (0.0932 + theta) ** 2)) / (2 * (0.0932 + theta))  # -Im s(x) = coil's + delay's
    assert x0 + 0.05 < base["coil_x"] < whole and base["baseline_E_refined"] > 2.0
    delay = candidate("channel_delay", beam_space(), BEAM.m, {"f0": BEAM.f0_hz})
    first = Objective(delay, build(READ_OUT)).fit(BEAM_JOINT, starts=3, max_nfev=40, refresh=1)  # as scored
    gain, runs, info = refine_slope(delay, first.theta, READ_OUT, build, max_nfev=40)
    fit = Objective(delay, runs).fit(first.theta, starts=1, max_nfev=40, refresh=1)
    got = dict(zip(delay.grown.names, fit.theta))["tau_s"]
    print(f"baseline: coil x {base['coil_x']:.3f}, E {base['baseline_E_refined']:.2f}; channel_delay: coil x "
          f"{info['coil_x']:.3f}, tau {got * 1e6:.1f} us (truth {tau * 1e6:.1f}), E {fit.E:.2f}")
    assert info["coil_x"] < 0.15
    assert got + info["coil_x"] / WC == pytest.approx(tau + tau_l, rel=0.05)
    assert fit.E < 1.3
    assert _relative(gain) == pytest.approx(drive.coil_slope(info["coil_x"]))


def test_a_slope_that_gains_nothing_is_not_taken(monkeypatch):
    """Envelopes driven through exactly the read-out's drive (the truth: a coil's slope, -0.09i relative); the coil
    step is forced to propose x 0.5 (a coil, so only the 'nothing gained' clause can refuse it). The baseline refit
    with that coil fits worse than with the truth, so the read-out's drive is kept."""
    read_out = (AC, -0.09j * AC / WC, WC)
    build = _campaign(lambda f: gain_at(read_out, f), seed=2)
    calls = []

    def step(obj, theta, gain, x):
        calls.append(x)
        return 0.5 - x
    monkeypatch.setattr(drive, "_coil_step", step)
    gain, runs, info = refine_slope(C0, BEAM_JOINT, read_out, build, max_nfev=20, rounds=1)
    assert len(calls) == 1
    coil = (AC, drive.coil_slope(0.5) * AC / WC, WC)
    tilted = Objective(C0, build(coil)).fit(BEAM_JOINT, starts=1, max_nfev=20, refresh=1).E
    assert tilted > info["baseline_E_read_out"]  # the coil gains nothing (the truth is the read-out's drive)
    assert gain == read_out
    assert info["baseline_E_refined"] == info["baseline_E_read_out"]
    assert np.array_equal(runs[0].equivalent_base, build(read_out)[0].equivalent_base)


def test_the_slope_is_refit_only_for_a_voltage_drive_whose_fast_model_is_within_the_scatter():
    """The clause `refits_slope` states (the stage and the words ask it): a voltage campaign, and a fast-model floor
    at most the repeat scatter (E 1); an unmeasured floor counts as 0; a force or base drive never."""
    assert drive.refits_slope("V", 0.5) and drive.refits_slope("V", 1.0) and drive.refits_slope("V", None)
    assert not drive.refits_slope("V", 1.01) and not drive.refits_slope("V", 30.0)
    assert not drive.refits_slope("lbf", 0.1) and not drive.refits_slope("g", 0.1)
