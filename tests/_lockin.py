"""A small, independent lock-in demodulator for tests (not jointcal code).

Complex amplitudes of signals at a known drive phase, averaged over a moving window
of whole-ish cycles; the quadrature crossing of z against the base acceleration.
"""
import numpy as np


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
