"""The ring-down read-out (jointcal.measure.ringdown) against closed forms: a linear mode's free decay, and
the exact Iwan simulator's ring-down after a dwell, held against the joint's first-harmonic balance."""
from __future__ import annotations

import numpy as np
import pytest

import pandas as pd

from jointcal.measure.ringdown import decay_start, ringdown_at, ringdown_backbone
from jointcal.models import IwanParams, MinistackModel, harmonic_balance, simulate
from jointcal.units import G

JOINT = dict(k=818.0, Fs=4.0, KT=204.0, chi=-0.5, beta=0.1, zeta_v=0.008, m=1.0 / G)  # a 100 Hz jointed beam


def test_a_linear_decay_gives_its_frequency_and_damping():
    fs, f0, z0, t_cut = 1024.0, 18.6, 0.005, 2.0
    t = np.arange(int(30 * fs)) / fs  # recorded until the decay has died into the noise
    wn = 2 * np.pi * f0
    wd = wn * np.sqrt(1 - z0**2)
    x = np.where(t < t_cut, np.cos(wn * t), np.exp(-z0 * wn * (t - t_cut)) * np.cos(wd * (t - t_cut) + wn * t_cut))
    noisy = x + 1e-4 * np.random.default_rng(0).standard_normal(t.size)
    bb = ringdown_backbone(noisy, fs, 18.0, start=int(t_cut * fs))
    assert len(bb) > 10 and bb["q_in"].is_monotonic_decreasing
    # the line (0.1%, 3%) down to where the noise floor stops the read-out
    assert np.abs(bb["f_hz"] / f0 - 1).max() < 1e-3 and np.abs(bb["zeta"] / z0 - 1).max() < 0.03
    # 5800x over the noise: three decades (6-period windows had read two, growing windows read on)
    assert np.log10(bb["q_in"].max() / bb["q_in"].min()) > 2.5
    # the amplitude: |x| = exp(-zeta wn (t - t_cut)) g at the window's centre, over wn^2 in inches; within 2e-3
    # over the top two decades, within 5e-3 below them, where the window's amplitude carries the noise's 0.1-0.5%
    q_true = np.exp(-z0 * wn * (bb["t_s"] - t_cut)) * G / wn**2
    err = np.abs(bb["q_in"] / q_true - 1)
    top = bb["q_in"] >= bb["q_in"].max() / 100
    assert err[top].max() < 2e-3 and err.max() < 5e-3
    assert bb["flags"].iloc[-1] == "noise_floor"  # it stopped at the noise, and says so


def test_other_modes_ringing_from_the_start_leave_the_mode_read_from_the_whole_record():
    """After an impact every mode rings from the cut: a continuation of one mode alone would start the others
    abruptly at the junction (zeta 11% off in the first window), so the record is band-passed whole and read
    after their onsets' ring (measured over 18 onset phases: f within 1.1e-4, zeta within 1.9%, 2.8 decades)."""
    fs, t_cut = 1024.0, 2.0
    t = np.arange(int(30 * fs)) / fs

    def free(f0, z0, a):
        wn = 2 * np.pi * f0
        return a * np.where(t < t_cut, 0.0, np.exp(-z0 * wn * (t - t_cut)) * np.sin(wn * np.sqrt(1 - z0**2) * (t - t_cut)))

    x = free(18.6, 0.005, 1.0) + free(41.0, 0.004, 1.5) + free(7.0, 0.01, 0.5)
    x += 1e-4 * np.random.default_rng(2).standard_normal(t.size)
    bb = ringdown_backbone(x, fs, 18.0, start=int(t_cut * fs))
    assert np.abs(bb["f_hz"] / 18.6 - 1).max() < 1e-3 and np.abs(bb["zeta"] / 0.005 - 1).max() < 0.03
    assert np.log10(bb["q_in"].max() / bb["q_in"].min()) > 2.5


@pytest.fixture(scope="module")
def iwan_ringdown():
    """A force dwell at 97.4 Hz (near resonance at 0.3 lbf) for 3 s, cut to zero; 5 s of free decay."""
    fs = 2048.0
    t = np.arange(int(8 * fs)) / fs
    force = 0.3 * np.clip(t / 0.2, 0, 1) * (t < 3.0) * np.sin(2 * np.pi * 97.4 * t)
    model = MinistackModel(m=JOINT["m"], k=JOINT["k"], zeta_v=JOINT["zeta_v"],
                           iwan=IwanParams(JOINT["Fs"], JOINT["KT"], JOINT["chi"], JOINT["beta"]))
    base_g = -force / (JOINT["m"] * G)  # a fixed-base oscillator driven by the force
    acc = simulate(model, base_g, fs).response_g - base_g
    acc += 1e-4 * np.std(acc) * np.random.default_rng(1).standard_normal(acc.size)
    return fs, force, acc


def test_the_exact_iwan_ring_down_reads_the_harmonic_balance_backbone(iwan_ringdown):
    fs, force, acc = iwan_ringdown
    assert decay_start(fs, acc, force) == int(3.0 * fs)
    # without the drive, from the response's envelope: within a cycle of the cut-off
    assert abs(decay_start(fs, acc) - int(3.0 * fs)) < fs / 97.4
    bb = ringdown_backbone(acc, fs, 98.0, drive=force)
    f_t, z_t = harmonic_balance(bb["q_in"].to_numpy(), JOINT["Fs"], JOINT["KT"], JOINT["chi"], JOINT["beta"],
                                JOINT["k"], JOINT["m"], JOINT["zeta_v"])
    top = bb["q_in"] >= bb["q_in"].max() / 10**2  # two decades below the largest amplitude
    assert np.abs(bb["f_hz"][top] / f_t[top] - 1).max() < 1e-3
    assert np.abs(bb["zeta"][top] / z_t[top] - 1).max() < 0.03
    assert bb["f_hz"][top].max() / bb["f_hz"][top].min() - 1 > 0.015  # the joint softens along the decay
    assert bb["zeta"][top].max() / bb["zeta"][top].min() > 1.4  # and dissipates more at large amplitude


def test_a_record_without_a_free_decay_is_said():
    fs = 1024.0
    t = np.arange(int(4 * fs)) / fs
    drive = np.sin(2 * np.pi * 18 * t)
    with pytest.raises(ValueError, match="no free decay"):
        decay_start(fs, drive, drive)
    with pytest.raises(ValueError, match="Nyquist"):
        ringdown_backbone(drive, fs, 600.0, start=0)


def test_a_force_gauge_left_on_the_shaker_reads_past_the_cut_and_the_decay_still_starts_at_it(tmp_path):
    # the force-driven beam of tests/_support/rigs.py dwelt at its resonance, then its voltage cut: the gauge goes on
    # reading the armature's reaction (at first above the dwell's force) while the structure rings down, so the
    # reference's last sample above DRIVE_OFF lies deep in the decay (before: a CampaignError at ingest, "the
    # drive's frequency over the dwell is 611 Hz", and a decay start in the noise)
    from jointcal.io import ingest_campaign, read_run
    from jointcal.spectral import DRIVE_OFF
    from jointcal.synth import generate
    from tests._support import rigs

    f, _ = rigs.truth_curve("force", rigs.Q_TARGETS[1])
    dwell_s = 1.5
    generate({"seed": 3, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": 0.02},
              "sweep": {"f_start_hz": 0.7 * f, "f_stop_hz": 1.3 * f, "rate_hz_per_s": 1.0},  # (the spec's band)
              "series": [{"level_V": rigs.levels_V()[1], "test": "dwell", "dwell_hz": [round(f, 3)],
                          "dwell_s": dwell_s, "decay_s": 2.5}],
              "assemblies": {"beam": rigs.JOINTED_BEAM},
              "rig": {"reference": "force", "shaker": rigs.SMALL_SHAKER, "second_mode": rigs.SECOND_MODE}},
             tmp_path / "c", tmp_path / "t.json")
    row = ingest_campaign(tmp_path / "c").iloc[0].to_dict()  # the dwell's frequency read over the dwell
    rec = read_run(tmp_path / "c" / row["file"], row)
    fs, force = row["sample_rate_hz"], rec["force_lbf"].to_numpy()
    late = np.flatnonzero(np.abs(force - np.median(force)) > DRIVE_OFF * np.abs(force).max())[-1] / fs
    assert late > dwell_s + 0.3  # the gauge stays live well past the cut
    from scipy import signal
    sos = signal.butter(4, [0.7 * f, 1.3 * f], "bandpass", fs=fs, output="sos")
    y = signal.sosfiltfilt(sos, rec["response_accel_g"].to_numpy())
    t0 = decay_start(fs, y, force - np.median(force)) / fs
    assert abs(t0 - dwell_s) <= 3 / f  # within three periods of the cut


def _power_law_decay(t_s, a0, f0, zeta_v, sigma_top, drop, p):
    """A free decay in closed form whose decay rate and frequency follow powers of its amplitude, as a microslip
    joint's do (zeta_joint ~ q^(chi+1)): d ln A/dt = -(s_v + S A^p), dphi/dt = w0 - W A^p, A(0) = a0.

    With v = A^p, k = p s_v and D = s_v + S v0 (1 - exp(-k t)): v = s_v v0 exp(-k t) / D and
    phi = w0 t - W ln(D / s_v) / (p S). Returns A(t) (g), phi(t) (rad) and sigma(A) (1/s), w(A) (rad/s)."""
    w0 = 2 * np.pi * f0
    s_v, v0 = zeta_v * w0, a0**p
    S, W = (sigma_top - s_v) / v0, drop * w0 / v0
    D = s_v + S * v0 * (1 - np.exp(-p * s_v * t_s))
    amp = (s_v * v0 * np.exp(-p * s_v * t_s) / D) ** (1 / p)
    return amp, w0 * t_s - W * np.log(D / s_v) / (p * S), (lambda a: s_v + S * a**p), (lambda a: w0 - W * a**p)


FS_PL, T_CUT = 2048.0, 1.0
PL = dict(a0=1.0, f0=100.0, zeta_v=0.0015, sigma_top=0.025 * 2 * np.pi * 91.0, drop=0.09, p=0.35)


@pytest.fixture(scope="module")
def power_law():
    """The closed-form decay after a dwell at its top amplitude and frequency (phase continuous at the cut)."""
    t = np.arange(int(4.0 * FS_PL)) / FS_PL
    amp, phi, sigma, w = _power_law_decay(np.maximum(t - T_CUT, 0.0), **PL)
    x = np.where(t < T_CUT, PL["a0"] * np.cos(w(PL["a0"]) * (t - T_CUT)), amp * np.cos(phi))
    return t, x, amp, sigma, w


def _read(bb):
    """The windows' amplitude (the signal's, g), decay rate (1/s) and damped frequency (rad/s)."""
    wn = 2 * np.pi * bb["f_hz"].to_numpy()
    sig = bb["zeta"].to_numpy() * wn
    return bb["q_in"].to_numpy() * wn**2 / G, sig, np.sqrt(wn**2 - sig**2)


def test_long_windows_read_a_fast_changing_decay_at_their_centre(power_law):
    """Windows of two e-folds (where the noise floor grows them) see the decay rate and frequency change along
    them, and not linearly: the log-envelope's third-order term projects onto its slope. Held at the curvature the
    neighbouring windows give, each reads the closed form at its centre: interior windows within 0.2% in the decay
    rate and 5e-5 in frequency (a quadratic log-envelope and phase alone: 0.5-1.1% and up to 8e-4 here)."""
    t, x, amp, sigma, w_of = power_law
    rows, t_c = [], T_CUT + 0.02
    while True:  # two e-folds long, one apart, down to 1e-4 of the top or the record's end
        a = np.interp(t_c, t, np.where(t < T_CUT, PL["a0"], amp))
        if a < 1e-4 or t_c + 2.0 / sigma(a) > t[-1] - 0.2:
            break
        rows.append(dict(t_s=t_c + 1.0 / sigma(a), window_s=2.0 / sigma(a)))
        t_c += 1.0 / sigma(a)
    a, sig, w = _read(ringdown_at(x, FS_PL, 95.0, pd.DataFrame(rows), start=int(T_CUT * FS_PL)))
    inner = slice(1, -1)  # the first and last windows have neighbours on one side only: a slope, no curvature
    assert len(rows) >= 6
    assert np.abs(sig[inner] / sigma(a[inner]) - 1).max() < 2e-3
    assert np.abs(w[inner] / w_of(a[inner]) - 1).max() < 5e-5
    assert np.abs(sig / sigma(a) - 1).max() < 1e-2



def test_the_first_windows_after_the_cut_read_a_decay_whose_frequency_rises_fast(power_law):
    """The whole estimator on the closed-form decay cut from its dwell (amplitude 15% down and frequency 0.5% up
    in its first period): the decay is band-passed apart after its own continuation backwards, which runs on at
    the first window's frequency and decay rate at the junction. Its first two windows read the closed form's
    frequency within 5e-5 (continued at the window centre's frequency: -4.6e-4 and +1.6e-4) and its decay rate
    within 0.5%."""
    t, x, amp, sigma, w_of = power_law
    bb = ringdown_backbone(x, FS_PL, 95.0, start=int(T_CUT * FS_PL))
    a, sig, w = _read(bb)
    assert bb["t_s"].iloc[0] - T_CUT < 3.0 / 91.0  # the first window centred within three periods of the cut
    assert np.abs(w[:2] / w_of(a[:2]) - 1).max() < 5e-5
    assert np.abs(sig[:2] / sigma(a[:2]) - 1).max() < 5e-3
