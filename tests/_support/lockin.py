"""A small, independent lock-in demodulator for tests (not jointcal code).

Complex amplitudes of signals at a known drive phase, averaged over a moving window
of whole-ish cycles; the quadrature crossing of z against the base acceleration.
"""
import numpy as np

from jointcal.units import G


def demodulate(x, phase, nwin):
    e = np.exp(-1j * phase)
    k = np.ones(nwin) / nwin
    return 2.0 * np.convolve(x * e, k, "same")


def quadrature(base, z, phase, finst, fs, f_guess, cycles=30):
    """Frequency (Hz) and |z| (in) where z leads the base acceleration by 90 degrees."""
    nw = int(fs * cycles / f_guess)
    A = demodulate(base, phase, nw)
    Z = demodulate(z, phase, nw)
    sl = slice(nw, len(base) - nw)
    ph = np.angle(Z[sl] / A[sl]) - np.pi / 2
    f = finst[sl]
    q = np.abs(Z[sl])
    i = np.where(ph[:-1] * ph[1:] <= 0)[0]
    i = i[np.argmin(np.abs(f[i] - f_guess))]
    w = ph[i] / (ph[i] - ph[i + 1])
    return f[i] + w * (f[i + 1] - f[i]), q[i] + w * (q[i + 1] - q[i]), np.abs(A[sl][i])


def linear_sweep(fa, fb, rate, fs, level):
    """Linear sweep from fa to fb (Hz) at rate (Hz/s): time, phase, f(t), signal."""
    T = abs(fb - fa) / rate
    t = np.arange(int(fs * T)) / fs
    sgn = 1.0 if fb > fa else -1.0
    phase = 2 * np.pi * (fa * t + 0.5 * sgn * rate * t**2)
    return t, phase, fa + sgn * rate * t, level * np.sin(phase)



def nominal_phase(df, row):
    """Drive phase (rad) and frequency (Hz) of a run's nominal linear sweep, per sample."""
    t = df["time_s"].to_numpy()
    f0, f1, rate = row["f_start_hz"], row["f_stop_hz"], row["sweep_rate_hz_per_s"]
    sgn = 1.0 if f1 > f0 else -1.0
    tt = np.minimum(t, abs(f1 - f0) / rate)
    return 2 * np.pi * (f0 * tt + 0.5 * sgn * rate * tt**2), f0 + sgn * rate * tt


def run_quadrature(df, row, f_guess, cycles=30):
    """Quadrature frequency (Hz), |z| (in) and |a_base| (g) of one recorded run.

    Demodulates at the manifest's nominal sweep; z is the relative acceleration
    (response - base) over -omega^2 at the drive frequency.
    """
    phase, finst = nominal_phase(df, row)
    base = df["base_accel_g"].to_numpy()
    rel = df["response_accel_g"].to_numpy() - base
    z = -rel * G / (2 * np.pi * finst) ** 2
    return quadrature(base, z, phase, finst, row["sample_rate_hz"], f_guess, cycles)


def run_amplitudes(df, row, freqs, cycles=40):
    """Complex response and base amplitudes (g) at the given drive frequencies of a run."""
    phase, finst = nominal_phase(df, row)
    nw = int(row["sample_rate_hz"] * cycles / np.mean(freqs))
    B = demodulate(df["base_accel_g"].to_numpy(), phase, nw)
    R = demodulate(df["response_accel_g"].to_numpy(), phase, nw)
    idx = [int(np.argmin(np.abs(finst - f))) for f in freqs]
    return R[idx], B[idx]
