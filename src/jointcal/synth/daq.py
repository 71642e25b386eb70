"""The measurement chain a shaker lab puts between the physics and the file.

Applied identically in structure to every channel: anti-alias filter (at the
simulation rate, the same filter on every channel) -> sampling -> broadband noise in
the recorded band (sensor and preamp noise, its RMS a set fraction of the channel's
RMS, as a user would measure it in the file) -> DC offset -> ADC quantisation with
clipping at the channel's full scale.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import signal

__all__ = ["controlled_sweep", "measure"]


def controlled_sweep(fs: float, f_start: float, f_stop: float, rate: float, level: float, *,
                     rng: np.random.Generator, ramp_s: float = 0.05, tail_s: float = 0.0,
                     ripple: float = 0.01, distortion: tuple[float, float] = (0.003, 0.002)):
    """Control-accelerometer signal of a linear swept sine under closed-loop control.

    The controller holds the amplitude at `level` within a slow ripple (fraction
    `ripple`, random phase, ~1 Hz) and the shaker adds 2nd and 3rd harmonic distortion
    (fractions of the fundamental); cosine ramps in and out, then `tail_s` of rest
    (the response rings down: a free decay at the end of the record).

    Returns
    -------
    t : ndarray, s;  f_inst : ndarray, drive frequency (Hz);  a : ndarray, g.
    """
    T = abs(f_stop - f_start) / rate
    t = np.arange(int(round((T + tail_s) * fs))) / fs
    sgn = np.sign(f_stop - f_start)
    tt = np.minimum(t, T)
    phase = 2 * np.pi * (f_start * tt + 0.5 * sgn * rate * tt**2)
    f_inst = f_start + sgn * rate * tt
    env = np.ones_like(t)
    n_r = int(ramp_s * fs)
    if n_r > 0:
        w = 0.5 - 0.5 * np.cos(np.pi * np.arange(n_r) / n_r)
        env[:n_r] *= w
        i_end = int(T * fs)
        env[max(i_end - n_r, 0):i_end] *= w[::-1][: i_end - max(i_end - n_r, 0)]
    env[t >= T] = 0.0
    ph = rng.uniform(0, 2 * np.pi, 3)
    amp = level * env * (1 + ripple * np.sin(2 * np.pi * 0.9 * t + ph[0]))
    a = amp * (np.sin(phase) + distortion[0] * np.sin(2 * phase + ph[1]) + distortion[1] * np.sin(3 * phase + ph[2]))
    return t, f_inst, a


def measure(x: NDArray, fs_sim: float, fs_out: float, *, rng: np.random.Generator, noise_fraction: float,
            dc_offset: float, full_scale_g: float, bits: int = 24, sos: NDArray | None = None) -> NDArray:
    """One channel through the DAQ: noise, offset, anti-alias filter, sampling, ADC.

    Parameters
    ----------
    x : ndarray
        True acceleration at the simulation rate fs_sim, g.
    noise_fraction : float
        Sensor noise standard deviation as a fraction of the channel's RMS.
    dc_offset : float
        The channel's DC offset, g (drawn by the caller, so it can be recorded).
    full_scale_g : float
        ADC range +/- full_scale_g; values beyond are clipped (as a real ADC does).
    sos : ndarray, optional
        Anti-alias filter (second-order sections) at fs_sim; the same for every channel.
    """
    q = int(round(fs_sim / fs_out))
    if abs(q * fs_out - fs_sim) > 1e-9 * fs_sim:
        raise ValueError(f"simulation rate {fs_sim} Hz must be an integer multiple of the output rate {fs_out} Hz.")
    y = signal.sosfilt(sos, x) if sos is not None else x
    y = y[::q]
    y = y + noise_fraction * np.sqrt(np.mean(y**2)) * rng.standard_normal(y.size)
    y = y + dc_offset
    lsb = 2.0 * full_scale_g / 2**bits
    return np.clip(np.round(y / lsb), -(2 ** (bits - 1)), 2 ** (bits - 1) - 1) * lsb


def antialias(fs_sim: float, fs_out: float, order: int = 8, cutoff: float = 0.42):
    """Butterworth low-pass at cutoff * fs_out, as second-order sections at fs_sim."""
    return signal.butter(order, cutoff * fs_out, fs=fs_sim, output="sos")
