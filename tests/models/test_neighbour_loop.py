"""A neighbouring mode in a voltage drive's shaker loop (`jointcal.models.Neighbour`, (N1)-(N2)):
the fast models against the closed form (N1), the time simulation of the same loop against the
describing function, and the closed form against the jointed beam's physical voltage rig.

(N1): with both modes at the driving point, the drive-point acceleration per unit drive is
Y = 1 / (1 / (T_s + N') + c'), c' = -armature + i back_emf w_r / w, T_s the mode without the loop,
N' the neighbour; the calibrated (loaded) mode is 1 / T = 1 / T_s + c'.
"""
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import least_squares

from jointcal.models import Neighbour, quasi_steady, simulate, steady_state
from jointcal.models.swept import quasi_steady_runs
from jointcal.synth.shaker import Shaker, StructureMode, rig_matrices
from tests._support.rigs import SECOND_MODE, SMALL_SHAKER, rig

MODEL = rig()[0]
LINEAR = replace(MODEL, iwan=None, k=MODEL.k + MODEL.iwan.KT)
F0 = LINEAR.f0_hz
NB = Neighbour(1.5 * F0, 4.0, 0.01, 0.05, 0.01, F0)


def _closed_form(f):
    """(N1) for the linear mode: T from the mode's own closed form, unloaded, the neighbour added, reloaded."""
    w, wn = 2 * np.pi * f, 2 * np.pi * F0
    T = w**2 / (wn**2 - w**2 + 2j * LINEAR.zeta_v * wn * w)  # the loaded (calibrated) mode's relative accel.
    c = -NB.armature + 1j * NB.back_emf * F0 / f
    N = NB.ratio * w**2 / ((2 * np.pi * NB.f_hz) ** 2 - w**2 + 2j * NB.zeta * 2 * np.pi * NB.f_hz * w)
    return 1.0 / (1.0 / (1.0 / (1.0 / T - c) + N) + c)


def test_loop_models_equal_the_closed_form_for_a_linear_mode():
    """steady_state, quasi_steady (rate 0) and the batched runs read 1 + (N1) (the channel's absolute
    convention) to 1e-12, across the band and the neighbour's antiresonance."""
    f = np.linspace(60.0, 150.0, 91)
    model = replace(LINEAR, neighbour=NB)
    Y = _closed_form(f)
    for T in (steady_state(model, f, 0.01).transmissibility, quasi_steady(model, f, 0.01),
              quasi_steady_runs(model, [(f, 0.01, 0.0, 0.0, "up")])[0]):
        np.testing.assert_allclose(T - 1.0, Y, rtol=1e-10)
    # without the loop the neighbour is the added term again
    plain = replace(LINEAR, neighbour=replace(NB, armature=0.0, back_emf=0.0))
    np.testing.assert_allclose(steady_state(plain, f, 0.01).transmissibility,
                               steady_state(LINEAR, f, 0.01).transmissibility + NB.frf(f), rtol=1e-12)


@pytest.mark.parametrize("level_g", [0.005, 0.05])
def test_time_simulation_of_the_loop_matches_the_describing_function(level_g):
    """The exact-Iwan time simulation of the two modes in the loop (`structure._loop_matrices`), dwelt to steady
    state, demodulated at the drive, equals `steady_state`'s describing-function solution of (N2) within 1e-4
    (the joint softens and damps between the levels)."""
    model = replace(MODEL, neighbour=NB)
    fs = 4096.0
    t = np.arange(0.0, 7.0, 1.0 / fs)
    last = t >= 4.0
    for f in (96.0, 99.0):
        u = level_g * np.sin(2 * np.pi * f * t) * np.minimum(1.0, t / 0.5)
        y = simulate(model, u, fs).response_g
        e = np.exp(-2j * np.pi * f * t[last])
        T = np.sum(y[last] * e) / np.sum(u[last] * e)
        expected = steady_state(model, [f], level_g).transmissibility[0]
        assert abs(T / expected - 1.0) < 1e-4, (f, T, expected)


def test_the_loop_represents_the_voltage_rig_with_a_second_mode():
    """The jointed beam's physical voltage rig (coil R, L, Bl, armature, suspension; `synth.shaker.rig_matrices`)
    with a second mode at 150 Hz (0.25 lbf): its exact linear FRF over 69-128 Hz, fitted by the linear mode with
    the looped neighbour (its frequency, ratio, loop constants) times a drive constant and slope, is matched within
    E 0.1 (0.07 dB / 0.5 deg); the same neighbour added to the response, without the loop, leaves E > 3."""
    structure, _, _ = rig()
    sh = Shaker(**{**Shaker().__dict__, **SMALL_SHAKER})
    A, bu, _, outs = rig_matrices(structure, sh, StructureMode(**{**SECOND_MODE, "f_hz": 150.0, "weight_lbf": 0.25}))
    f = np.linspace(69.0, 128.0, 200)
    w = 2 * np.pi * f
    H = np.array([outs["accel"][0] @ np.linalg.solve(1j * x * np.eye(A.shape[0]) - A, bu) for x in w])
    wc = w[np.argmax(np.abs(H))]

    def response(p, looped):
        f1, z1, ar, ai, sr, si, fr, r, mu, be = p
        lin = replace(LINEAR, k=LINEAR.m * (2 * np.pi * f1) ** 2, zeta_v=z1)
        nb = Neighbour(fr * f1, r, 0.01, mu if looped else 0.0, be if looped else 0.0, f1)
        a = (ar + 1j * ai) * (1.0 + (sr + 1j * si) * (w - wc) / wc)
        return a * (steady_state(replace(lin, neighbour=nb), f, 1.0).transmissibility - 1.0)

    def fit(looped):
        f1 = wc / (2 * np.pi)
        T1 = w**2 / (wc**2 - w**2 + 0.02j * wc * w)
        a0 = np.vdot(T1, H) / np.vdot(T1, T1)

        def res(p):
            d = response(p, looped) / H
            return np.concatenate([20 * np.log10(np.abs(d)) / 0.07, np.degrees(np.angle(d)) / 0.5])
        best = min((least_squares(res, [f1, 0.01, a0.real, a0.imag, 0.0, 0.0, 1.5, 2.0, m0, m0], x_scale="jac",
                                  bounds=([50, 1e-4, -np.inf, -np.inf, -5, -5, 1.05, -20, 0, 0],
                                          [150, 0.2, np.inf, np.inf, 5, 5, 3.0, 20, 0.9, 0.5]), max_nfev=600)
                    for m0 in (0.0, 0.05)), key=lambda s: s.cost)
        return np.sqrt(2 * best.cost / (2 * f.size)), best.x

    E_loop, p = fit(True)
    E_added, _ = fit(False)
    print(f"E loop {E_loop:.3f} (armature {p[8]:.3f}, back_emf {p[9]:.4f}), added {E_added:.2f}")
    assert E_loop < 0.1, (E_loop, p)
    assert E_added > 3.0, E_added


def test_a_read_out_constant_off_the_modes_own_divides_the_drive():
    """kappa (the read-out's drive constant over the mode's own): the model driven by e reads as the model with
    kappa = 1 driven by e / kappa, its response over e divided by kappa where the mode is linear; with the joint, at
    the level that reaches the same amplitude (the fast model and the time simulation alike)."""
    f = np.linspace(80.0, 120.0, 41)
    kappa = 1.3 * np.exp(0.07j)
    nb1 = NB
    nbk = replace(NB, read_gain=abs(kappa), read_phase=np.angle(kappa))
    lin1, link = replace(LINEAR, neighbour=nb1), replace(LINEAR, neighbour=nbk)
    for fn in (lambda m, lev: steady_state(m, f, lev).transmissibility, lambda m, lev: quasi_steady(m, f, lev)):
        np.testing.assert_allclose(fn(link, 0.01) - 1.0, (fn(lin1, 0.01) - 1.0) / kappa, rtol=1e-10)
    # the jointed mode: driven by e / kappa, it is the kappa = 1 model at the level |e| / |kappa| (a constant turn
    # of the drive turns the response with it and leaves the ratio), read per e
    T1 = steady_state(replace(MODEL, neighbour=nb1), f, 0.05 / abs(kappa)).transmissibility
    Tk = steady_state(replace(MODEL, neighbour=nbk), f, 0.05).transmissibility
    np.testing.assert_allclose(Tk - 1.0, (T1 - 1.0) / kappa, rtol=1e-8)
    fs = 4096.0
    t = np.arange(0.0, 6.0, 1.0 / fs)
    last = t >= 3.5
    u = 0.05 * np.sin(2 * np.pi * 99.0 * t) * np.minimum(1.0, t / 0.5)
    y = simulate(replace(MODEL, neighbour=nbk), u, fs).response_g
    e = np.exp(-2j * np.pi * 99.0 * t[last])
    T = np.sum(y[last] * e) / np.sum(u[last] * e)
    expected = steady_state(replace(MODEL, neighbour=nbk), [99.0], 0.05).transmissibility[0]
    assert abs(T / expected - 1.0) < 1e-4, (T, expected)


def test_a_loop_that_makes_the_rig_active_is_refused_in_time():
    """A back-EMF damping above the mode's own viscous damping leaves the structure without the shaker a negative
    dashpot: the time simulation refuses it in one sentence rather than integrating a growing response."""
    bad = replace(MODEL, neighbour=replace(NB, back_emf=0.5))
    with pytest.raises(ValueError, match="unstable"):
        simulate(bad, np.zeros(64), 2048.0)
