"""Swept-sine envelopes: drive-frequency ridge and complex amplitudes along the sweep.

Per run: the drive frequency is tracked from the reference channel's spectrogram
ridge (`scipy.signal.ShortTimeFFT`; the manifest's nominal sweep is not trusted: real
controllers deviate and a record may end in free decay); its integral is the drive
phase, against which every channel is demodulated with the same window (a
chirp-following lock-in: the STFT's value at the ridge, free of scalloping). The 2nd
and 3rd harmonics of the response are demodulated at 2x and 3x the drive phase.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import NDArray
from scipy.signal import ShortTimeFFT, savgol_filter
from scipy.signal.windows import hann

from ..io._clipping import clipped_mask
from ..io.contract import REFERENCE, RESPONSE, excitation_kind
from ..spectral import parabola_vertex
from ..units import G

__all__ = ["EnvelopeMeta", "window_length", "track_drive", "envelopes", "meta_dict", "ENVELOPE_COLUMNS",
           "ZETA_MIN"]

ZETA_MIN = 0.01  # smallest damping ratio expected: sets the window (the config's envelopes.zeta_min default)

ENVELOPE_COLUMNS = ("time_s", "f_drive_hz", "ref_re", "ref_im", "resp_re", "resp_im", "z_re", "z_im", "h2_amp_g",
                    "h3_amp_g", "noise_g", "drive_on", "bad")  # one row per frame


@dataclass(frozen=True)
class EnvelopeMeta:
    """How a run's envelopes were made (written next to them)."""

    window_s: float
    hop_s: float
    n_window: int
    mfft: int
    fs_hz: float
    excitation: str
    rate_hz_per_s: float  # measured from the ridge
    n_frames: int
    n_drive_on: int


def window_length(fs: float, rate: float, f_low: float, *, zeta_min: float = ZETA_MIN) -> int:
    """Window length (samples) for a sweep at `rate` Hz/s sampled at `fs` Hz.

    The window must be shorter than the time the sweep takes to cross a half-power
    band 2 zeta f (a quarter of it, at the band's low end and the smallest expected
    damping `zeta_min`) and than the chirp-matched length 1/sqrt(rate) (the frequency
    moves one bin per window); and at least 8 cycles of the lowest frequency.
    """
    t_cross = 2.0 * zeta_min * f_low / rate
    t = min(1.0 / np.sqrt(rate), t_cross / 4.0)
    t = float(np.clip(t, 8.0 / f_low, 2.0))
    n = int(round(t * fs))
    return n + (n % 2)


def _frames(x: NDArray, n: int, hop: int) -> NDArray:
    """Frames of length n every hop samples, the first centred on sample n//2."""
    return sliding_window_view(x, n, axis=-1)[..., ::hop, :]


def track_drive(ref: NDArray, fs: float, n_win: int, hop: int, f_band: tuple[float, float]):
    """Drive frequency along the record from the reference channel's spectrogram ridge.

    Returns
    -------
    t_c : ndarray, frame centres (s);  f : ndarray, ridge frequency (Hz), smoothed;
    mag : ndarray, ridge magnitude (reference units, amplitude-scaled).
    """
    win = hann(n_win, sym=False)
    mfft = 1 << int(np.ceil(np.log2(4 * n_win)))
    stft = ShortTimeFFT(win, hop, fs, mfft=mfft, scale_to="magnitude")
    lo, hi = f_band
    p0 = stft.lower_border_end[1]
    p1 = stft.upper_border_begin(ref.size)[1]
    S = np.abs(stft.stft(ref, p0=p0, p1=p1))
    f_axis = stft.f
    band = (f_axis >= 0.7 * lo) & (f_axis <= min(1.3 * hi, 0.49 * fs))
    ib = np.flatnonzero(band)
    k = ib[np.argmax(S[ib], axis=0)]
    k = np.clip(k, 1, S.shape[0] - 2)
    j = np.arange(S.shape[1])
    delta, top = parabola_vertex(*(np.log(S[k + d, j] + 1e-300) for d in (-1, 0, 1)))  # Gaussian-peak refinement
    f = (k + np.clip(delta, -0.5, 0.5)) * stft.delta_f
    mag = 2.0 * np.exp(top)
    t_c = stft.t(ref.size, p0=p0, p1=p1)
    return t_c, f, mag, mfft


def _smooth_ridge(t: NDArray, f: NDArray, on: NDArray) -> NDArray:
    """Robust smoothing of the ridge over drive-on frames; held constant outside."""
    out = f.copy()
    idx = np.flatnonzero(on)
    if idx.size >= 7:
        fo = f[idx]
        med = pd.Series(fo).rolling(7, center=True, min_periods=1).median().to_numpy()
        bad = np.abs(fo - med) > 5.0 * (np.median(np.abs(np.diff(fo))) + 1e-9)
        fo = np.where(bad, med, fo)
        w = min(31, idx.size - (1 - idx.size % 2))
        w = w if w % 2 else w - 1
        fo = savgol_filter(fo, w, 2) if w >= 5 else fo
        out[idx] = fo
        out[: idx[0]] = fo[0]
        out[idx[-1] + 1:] = fo[-1]
    return out


def envelopes(df: pd.DataFrame, row: dict, *, zeta_min: float = ZETA_MIN, hop_fraction: float = 0.25):
    """Envelopes of one run.

    Parameters
    ----------
    df : DataFrame
        The run record: time_s, base_accel_g (or force_lbf, or drive_V), response_accel_g.
    row : mapping
        Its manifest row (f_start_hz, f_stop_hz, sweep_rate_hz_per_s, sample_rate_hz).
    zeta_min : float
        Smallest damping ratio expected; sets the window (see `window_length`).

    Returns
    -------
    env : DataFrame, one row per frame
        time_s, f_drive_hz, ref_re/ref_im (base g, force lbf or drive V), resp_re/resp_im
        (g), z_re/z_im (relative displacement, in; for force- and voltage-driven runs the
        response displacement), h2_amp_g, h3_amp_g (response harmonics), noise_g (response at
        1.5x the drive: the noise floor), drive_on, bad (frames touching NaN or clipped
        samples).
    meta : EnvelopeMeta
    """
    fs = float(row["sample_rate_hz"])
    kind = excitation_kind(df.columns)
    ref = df[REFERENCE[kind]].to_numpy(dtype=float)
    resp = df[RESPONSE].to_numpy(dtype=float)
    # NaN/inf and clipped samples (the ingest stage's definition) are left out
    bad_sample = ~np.isfinite(ref) | ~np.isfinite(resp) | clipped_mask(ref) | clipped_mask(resp)
    ref = np.where(np.isfinite(ref), ref, 0.0)
    resp = np.where(np.isfinite(resp), resp, 0.0)
    ref = ref - np.median(ref)  # DC offsets do not enter the demodulation, but do the ridge
    resp = resp - np.median(resp)
    lo, hi = sorted((float(row["f_start_hz"]), float(row["f_stop_hz"])))
    rate_nom = float(row["sweep_rate_hz_per_s"])
    n = window_length(fs, rate_nom, lo, zeta_min=zeta_min)
    if n >= ref.size // 4:
        raise ValueError(f"run {row.get('run_id', '?')}: record of {ref.size} samples is too short for a "
                         f"{n}-sample window; record a longer sweep or lower the sweep rate.")
    hop = max(1, int(n * hop_fraction))
    t_c, f_r, mag, mfft = track_drive(ref, fs, n, n, (lo, hi))  # the ridge is smooth: hop one window
    on = mag > 0.2 * np.median(mag[mag > 0.5 * np.max(mag)])
    f_d = _smooth_ridge(t_c, f_r, on)
    # drive phase at every sample, integrated from the ridge (frame centres are at n//2 + j*hop)
    t = np.arange(ref.size) / fs
    f_s = np.interp(t, t_c, f_d)
    phase = 2 * np.pi * np.cumsum(f_s) / fs
    win = hann(n, sym=False)
    scale = 2.0 / win.sum()
    base = np.exp(-1j * phase)
    sig = np.stack([ref * base, resp * base, resp * base**2, resp * base**3, resp * base * np.exp(-1j * phase / 2)])
    amp = _frames(sig, n, hop) @ win * scale  # (5, frames)
    nf = amp.shape[1]
    centres = n // 2 + hop * np.arange(nf)
    t_f = centres / fs
    f_f = np.interp(t_f, t_c, f_d)
    on_f = np.interp(t_f, t_c, on.astype(float)) > 0.5
    bad_f = _frames(bad_sample.astype(float), n, hop).max(axis=-1) > 0
    R, Rref = amp[1], amp[0]
    w2 = (2 * np.pi * f_f) ** 2
    Z = -(R - Rref) * G / w2 if kind == "base" else -R * G / w2
    env = pd.DataFrame(dict(time_s=t_f, f_drive_hz=f_f, ref_re=Rref.real, ref_im=Rref.imag, resp_re=R.real,
                            resp_im=R.imag, z_re=Z.real, z_im=Z.imag, h2_amp_g=np.abs(amp[2]),
                            h3_amp_g=np.abs(amp[3]), noise_g=np.abs(amp[4]), drive_on=on_f, bad=bad_f))
    rate_meas = float(np.median(np.abs(np.diff(f_d[on])) / np.diff(t_c[on]))) if on.sum() > 2 else rate_nom
    meta = EnvelopeMeta(window_s=n / fs, hop_s=hop / fs, n_window=n, mfft=mfft, fs_hz=fs, excitation=kind,
                        rate_hz_per_s=rate_meas, n_frames=nf, n_drive_on=int(on_f.sum()))
    return env, meta


def meta_dict(meta: EnvelopeMeta) -> dict:
    """The metadata as a plain dict (for JSON)."""
    return asdict(meta)
