"""Swept-mode fit (jointcal.measure.sweepfit): a fast chirp's whole transient against closed forms and the
harmonic balance of the exact Iwan joint."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from jointcal.measure.sweepfit import fit_swept_mode
from jointcal.models import G, IwanParams, MinistackModel, fractional_delay, harmonic_balance, simulate
from jointcal.synth.daq import controlled_sweep
from tests._support.jacobian import assert_matches_central_difference


def _force_chirp(model: MinistackModel, f_lo: float, f_hi: float, rate: float, fs: float, force: float,
                 noise: float = 0.003, seed: int = 0):
    """Constant-amplitude force chirp on the slug (fixed base == base excited by -F/m), exact time
    integration, the slug's acceleration (g) with noise."""
    rng = np.random.default_rng(seed)
    t, _, F = controlled_sweep(fs, f_lo, f_hi, rate, force, rng=rng, ramp_s=0.01, tail_s=0.3, ripple=0.0,
                               distortion=(0.0, 0.0))
    acc = simulate(model, -F / (model.m * G), fs).response_g + F / (model.m * G)
    return F, acc + noise * acc.std() * rng.standard_normal(acc.size)


def test_linear_mode_at_eta_20_is_its_pole():
    """A linear 100 Hz, zeta 1.5% SDOF swept at eta 20: the fit returns the closed-form pole and no
    amplitude dependence, from start values 3% and a factor 2 off."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    F, acc = _force_chirp(model, 70.0, 130.0, 20 * (f0 * zeta) ** 2, 1024.0, 1.0)
    fit = fit_swept_mode(F, acc, 1024.0, 1.03 * f0, 2 * zeta, modal_phase=0.0)
    assert fit.f_hz == pytest.approx(f0, rel=2e-4) and fit.zeta == pytest.approx(zeta, rel=0.02)
    f_lo, z_lo = fit.backbone(fit.q_low_in)
    assert f_lo == pytest.approx(f0, rel=5e-4) and z_lo == pytest.approx(zeta, rel=0.05)
    assert fit.residual < 0.02


@pytest.mark.parametrize("eta", [1.0, 20.0])
def test_iwan_joint_chirp_gives_the_harmonic_balance_at_the_amplitude_reached(eta):
    """The Table 3.2 joint (exact Iwan integration) under a 4 lbf force chirp: resonance and damping at
    the amplitude reached within 0.2% / 5% of the first-harmonic balance there, and the fitted backbone
    follows the harmonic balance down to a third of that amplitude (softening, damping falling)."""
    p = IwanParams(313.0, 1.02e6, -0.65, 0.004)
    model = MinistackModel(m=2.65 / G, k=6.12e5, zeta_v=0.0015, iwan=p)
    rate = eta * (2250.0 * 0.015) ** 2
    F, acc = _force_chirp(model, 1700.0, 2700.0, rate, 25600.0, 4.0)
    fit = fit_swept_mode(F, acc, 25600.0, 2250.0, 0.015, modal_phase=0.0)  # a force: A = 1/m
    f_t, z_t = harmonic_balance(fit.q_in, p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    print(f"\neta {eta}: q {fit.q_in:.2e} in, f err {100 * (fit.f_hz / f_t - 1):+.4f}%, zeta err "
          f"{100 * (fit.zeta / z_t - 1):+.2f}%, residual {fit.residual:.3f}")
    assert fit.f_hz == pytest.approx(float(f_t), rel=2e-3) and fit.zeta == pytest.approx(float(z_t), rel=0.05)
    q3 = fit.q_in / 3
    f3, z3 = fit.backbone(q3)
    f3_t, z3_t = harmonic_balance(q3, p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    print(f"q/3: f err {100 * (f3 / f3_t - 1):+.4f}%, zeta err {100 * (z3 / z3_t - 1):+.2f}%")
    assert f3 == pytest.approx(float(f3_t), rel=1e-3) and z3 == pytest.approx(float(z3_t), rel=0.05)
    assert f3 > fit.f_hz and z3 < fit.zeta


@pytest.mark.parametrize("lag_deg", [0.0, 14.0])
def test_a_response_channel_lagging_the_force_is_read_as_a_phase_of_a_not_as_damping(lag_deg):
    """The Table 3.2 joint (exact Iwan integration) under a 4 lbf force chirp at eta 20, its response channel
    delayed by tau (an exact fractional delay; 14 deg at 2250 Hz, as the jointed beam's 4e-4 s at 98.5 Hz): the
    resonance and damping at the amplitude reached within 0.2% / 5% of the harmonic balance there, |A| within
    2% of 1/m, and A's phase -w tau within 1 deg. Without a delay A stays real (its phase does not earn its
    place) and the read-out is the one with the phase held at 0."""
    p = IwanParams(313.0, 1.02e6, -0.65, 0.004)
    model = MinistackModel(m=2.65 / G, k=6.12e5, zeta_v=0.0015, iwan=p)
    fs, tau = 25600.0, np.radians(lag_deg) / (2 * np.pi * 2250.0)
    F, acc = _force_chirp(model, 1700.0, 2700.0, 20 * (2250.0 * 0.015) ** 2, fs, 4.0)
    if tau:
        acc = fractional_delay(acc, tau, fs)
    fit = fit_swept_mode(F, acc, fs, 2250.0, 0.015, modal_phase=0.0)
    f_t, z_t = harmonic_balance(fit.q_in, p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    lag = -np.degrees(np.angle(fit.modal_constant))
    print(f"\nlag {lag_deg} deg: f err {100 * (fit.f_hz / f_t - 1):+.4f}%, zeta err {100 * (fit.zeta / z_t - 1):+.2f}%, "
          f"|A| m {abs(fit.modal_constant) * model.m:.4f}, A's lag {lag:.2f} deg (w tau "
          f"{np.degrees(2 * np.pi * fit.f_hz * tau):.2f}), residual {fit.residual:.4f}")
    assert fit.f_hz == pytest.approx(float(f_t), rel=2e-3) and fit.zeta == pytest.approx(float(z_t), rel=0.05)
    assert abs(fit.modal_constant) * model.m == pytest.approx(1.0, rel=0.02)
    assert lag == pytest.approx(np.degrees(2 * np.pi * fit.f_hz * tau), abs=1.0)
    if not tau:
        assert fit.modal_constant.imag == 0.0


def test_a_response_channel_leading_the_force_is_not_read_as_a_delay():
    """The same chirp with the response channel ADVANCED by the same 14 deg: no channel's delay leads, so A's phase
    is not freed for it (`sweepfit._lags`) and A stays real, as a force's 1/m is; the lead is left in the
    misfit (here larger than with the lag read as A's phase), for the discrepancy stage's library to explain."""
    p = IwanParams(313.0, 1.02e6, -0.65, 0.004)
    model = MinistackModel(m=2.65 / G, k=6.12e5, zeta_v=0.0015, iwan=p)
    fs, tau = 25600.0, -np.radians(14.0) / (2 * np.pi * 2250.0)
    F, acc = _force_chirp(model, 1700.0, 2700.0, 20 * (2250.0 * 0.015) ** 2, fs, 4.0)
    fit = fit_swept_mode(F, fractional_delay(acc, tau, fs), fs, 2250.0, 0.015, modal_phase=0.0)
    lagged = fit_swept_mode(F, fractional_delay(acc, -tau, fs), fs, 2250.0, 0.015, modal_phase=0.0)
    assert fit.modal_constant.imag == 0.0 and lagged.modal_constant.imag < 0.0
    assert fit.residual > 2 * lagged.residual


def test_a_record_without_drive_is_refused():
    with pytest.raises(ValueError, match="drive"):
        fit_swept_mode(np.zeros(1000), np.ones(1000), 1024.0, 100.0, 0.01)


def test_a_record_under_six_samples_per_cycle_is_integrated_on_finer_steps():
    """100 Hz at 400 Hz sampling (4 per cycle, the RK4 step would be unstable): the envelopes are
    interpolated to finer steps and the pole is still the closed form."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, 2000.0, 1.0)
    fit = fit_swept_mode(F[::5], acc[::5], 400.0, f0, zeta, modal_phase=0.0)
    assert fit.f_hz == pytest.approx(f0, rel=5e-4) and fit.zeta == pytest.approx(zeta, rel=0.03)


@pytest.mark.parametrize("channel", ["drive", "response", "both"])
def test_nan_bursts_are_left_out_not_filled(channel):
    """NaN bursts (a DAQ dropout of 40 ms, 4 cycles) across the resonance passage: the response's are left out
    of the misfit, the drive's envelope bridged, and the pole is still the closed form (filling the drive
    with zeros put the damping 29% low and the frequency 0.6% high)."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    fs = 1024.0
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, fs, 1.0)
    i_peak = int(np.argmax(np.abs(acc)))
    burst = slice(i_peak - int(0.06 * fs), i_peak - int(0.02 * fs))  # just before the response's peak
    F, acc = F.copy(), acc.copy()
    if channel in ("drive", "both"):
        F[burst] = np.nan
    if channel in ("response", "both"):
        acc[burst] = np.nan
    fit = fit_swept_mode(F, acc, fs, f0, zeta, modal_phase=0.0)
    assert fit.f_hz == pytest.approx(f0, rel=3e-4) and fit.zeta == pytest.approx(zeta, rel=0.03)
    assert (fit.fraction_bad > 0) == (channel in ("response", "both"))


def test_a_nan_burst_over_the_peak_leaves_the_amplitude_reached():
    """A 60 ms dropout of the response centred on its peak: the frames within a filter length of it leave
    the misfit, but q_in is the fitted response's peak over the whole window, the amplitude the mode
    reached: within 3% of the clean record's band-limited envelope peak |a| G / w0^2 (the largest good
    sample left put it 9% low)."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    fs = 1024.0
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, fs, 1.0, noise=0.0)
    sos = signal.butter(4, [0.8 * f0, 1.2 * f0], btype="band", fs=fs, output="sos")
    env = np.abs(signal.hilbert(signal.sosfiltfilt(sos, acc)))
    q_truth = env.max() * G / (2 * np.pi * f0) ** 2
    i_peak = int(np.argmax(env))
    acc = acc + 0.003 * acc.std() * np.random.default_rng(1).standard_normal(acc.size)
    acc[i_peak - int(0.03 * fs):i_peak + int(0.03 * fs)] = np.nan
    fit = fit_swept_mode(F, acc, fs, f0, zeta, modal_phase=0.0)
    assert fit.fraction_bad > 0.05
    assert fit.q_in == pytest.approx(q_truth, rel=0.03)
    assert fit.f_hz == pytest.approx(f0, rel=5e-4) and fit.zeta == pytest.approx(zeta, rel=0.05)


def test_a_record_cut_before_its_free_decay_is_said():
    """A record that ends 50 ms (5 cycles) after the response's peak has lost the free decay that fixes the
    damping: the fit says so (ringing_end), the whole record does not."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    fs = 1024.0
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, fs, 1.0)
    assert not fit_swept_mode(F, acc, fs, f0, zeta, modal_phase=0.0).ringing_end
    end = int(np.argmax(np.abs(acc))) + int(0.05 * fs)
    assert fit_swept_mode(F[:end], acc[:end], fs, f0, zeta, modal_phase=0.0).ringing_end


def test_a_record_that_begins_with_the_mode_moving_fits_its_start_state():
    """A record cut to begin 0.2 s before the response's peak (the mode already at a third of it, the
    drive on): its state there is not rest. The fit from rest misses the response at the record's start
    (by 58% of the peak), so it is refitted from a low-pass reach in, from a fitted state, and gives the
    closed-form pole (from rest the resonance came out 0.34% low here; on the real beam records cut to
    begin at 10% of the peak's level, -0.2..-0.4%). The whole record, from rest, is not refitted."""
    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    fs = 1024.0
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, fs, 1.0)
    cut = int(np.argmax(np.abs(acc))) - int(0.2 * fs)
    fit = fit_swept_mode(F[cut:], acc[cut:], fs, f0, zeta, modal_phase=0.0)
    assert fit.f_hz == pytest.approx(f0, rel=3e-4) and fit.zeta == pytest.approx(zeta, rel=0.03)
    assert fit.start_fitted and not fit_swept_mode(F, acc, fs, f0, zeta, modal_phase=0.0).start_fitted


@pytest.mark.parametrize("modal_phase", [None, 0.3])
def test_the_sensitivity_jacobian_is_the_central_difference_of_the_same_model(modal_phase):
    """The misfit's Jacobian by the RK4 step's forward sensitivities against a Richardson-extrapolated central
    difference of the misfit itself (the same discrete model, integrated apart by `rotating_mode`), column by
    column, at an amplitude-dependent point (every shape coefficient nonzero) with the start state fitted: all
    22 parameters (a voltage: complex constant and slope) or the 15 of a fixed phase (with the channels' phase,
    `PHASE`, freed). The amplitude limits are
    widened so that no finite-difference step crosses a kink of the held ends. The response the sensitivity
    kernel integrates is the plain kernel's, to the last bit."""
    from dataclasses import replace

    from jointcal.measure._rotating import demodulate, passage, rotating_mode
    from jointcal.measure._rotating_sensitivity import rotating_mode_sensitivity
    from jointcal.measure._sweep_problem import NP, PHASE, Problem

    f0, zeta, m = 100.0, 0.015, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    F, acc = _force_chirp(model, 70.0, 130.0, 5 * (f0 * zeta) ** 2, 1024.0, 1.0)
    cut = int(np.argmax(np.abs(acc))) - int(0.2 * 1024)
    sig = demodulate(F[cut:], acc[cut:], 1024.0, f0, zeta, 0.45, 6.0)
    prob = Problem.build(passage(sig, 0.15, 0.02, 6.0, True), f0, zeta, 0.15, modal_phase, 0.01, 0.3, 0.3)
    prob = replace(prob, l_lo=-40.0, l_hi=5.0)
    assert prob.ps.free_start
    free = prob.free_all if modal_phase is None else np.union1d(prob.free_all, [PHASE])
    p = np.zeros(NP)
    p[[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 15]] = [0.004, -0.1, -0.01, -0.002, 0.1, 0.01, 1.1, 0.2, 0.4, 0.05, -0.03,
                                                   -3e-4]
    p[[11, 12, 13, 14, 16, 17, 18, 19, 20, 21]] = [0.02, -0.01, 0.01, 0.005, -0.01, 0.003, 0.3, -0.2, 0.1, 0.2]
    pf = p[free]
    misfit = prob.misfit(pf, free)
    assert np.abs(misfit).max() < 10  # a point the model follows, not a diverged one
    assert_matches_central_difference(prob, pf, free)
    mode, _ = prob.params(pf, free)
    s, ps = prob.ps.sig, prob.ps
    z0, y0 = prob._start(p)
    plain = rotating_mode(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, prob.q_ref, prob.l_lo, prob.l_hi, z0, y0)
    sens = rotating_mode_sensitivity(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, prob.q_ref, prob.l_lo, prob.l_hi, z0,
                                     y0, np.arange(16), np.eye(16), np.flatnonzero(ps.sel))
    assert np.array_equal(plain[0], sens[0]) and np.array_equal(plain[1], sens[1])


def test_a_slow_chirp_read_with_the_sensitivity_jacobian_is_its_pole():
    """A linear 100 Hz, zeta 3% SDOF under a slow force chirp (eta 0.5): with the exact Jacobian the fit
    gives the closed-form pole, and the same read-out as with forward differences (within 1e-5 in f,
    1e-3 in zeta: the two Jacobians end the same least squares at the same optimum)."""
    f0, zeta, m = 100.0, 0.03, 1.0 / G
    model = MinistackModel(m=m, k=m * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    F, acc = _force_chirp(model, 80.0, 120.0, 0.5 * (f0 * zeta) ** 2, 1024.0, 1.0)
    fits = {jac: fit_swept_mode(F, acc, 1024.0, 1.01 * f0, 1.5 * zeta, modal_phase=0.0, jacobian=jac)
            for jac in ("sensitivity", "2-point")}
    exact, fd = fits["sensitivity"], fits["2-point"]
    assert exact.f_hz == pytest.approx(f0, rel=2e-4) and exact.zeta == pytest.approx(zeta, rel=0.02)
    assert exact.f_hz == pytest.approx(fd.f_hz, rel=1e-5) and exact.zeta == pytest.approx(fd.zeta, rel=1e-3)
    with pytest.raises(ValueError, match="jacobian"):
        fit_swept_mode(F, acc, 1024.0, f0, zeta, jacobian="3-point")
