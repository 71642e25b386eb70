"""Whole-record frequency response of a run and a single-mode fit of its peak.

What a lab's FRF software does with a swept-sine or chirp record:

* ``h1_estimate``: the H1 estimate of response / reference over the whole record
  (`scipy.signal.csd` / `scipy.signal.welch` with ONE boxcar segment holding the whole
  sweep and its free decay, zero-padded). For a linear structure excited from rest
  whose response has died out by the record's end this is the exact FRF at any sweep
  rate: no sweep-rate bias, unlike time-local envelopes or Welch averages of shorter
  segments (which bias a lightly damped peak by a few % because each segment cuts the
  ring-down). With one segment H1 = H2 and the coherence is 1 by construction, so H2
  and the coherence are also given from spectra averaged over `n_band` neighbouring
  lines (a Daniell estimate): diagnostics of noise on the reference (H1 < H2) and of
  distortion, not the values fitted. They carry a resolution bias where H changes
  within n_band / T Hz (T the record length): over a short chirp the coherence dips at
  a sharp peak without any noise (measured: 0.83 at a zeta = 1.5%, 100 Hz peak over a
  4 s record; > 0.99 over a 90 s one).
* ``pair_backbone`` (`jointcal.measure.backbone`): a voltage reference's bent peak, pole by
  pole over the amplitudes the peak region spans (see below).
* ``fit_mode`` (`jointcal.measure.modefit`, re-exported here): resonance and damping from a single-degree-of-freedom rational fit
  of the peak region of the displacement ratio (receptance, or relative displacement
  over base acceleration), with residual terms for the modes outside the band:
  ``X(w) = A / (w_n^2 - w^2 + 2 i zeta w_n w) + R_0 + R_2 / w^2`` with complex A, R_0,
  R_2 (a complex modal constant covers an amplifier voltage reference, whose phase to
  the force is not zero). w_n and zeta by least squares, the linear terms by variable
  projection; the fit's relative RMS residual is reported.

For a nonlinear structure (a bolted joint) the H1 of a sweep is the equivalent FRF at
that drive level: each line is the response to the drive at that frequency at the
amplitude the structure had when the sweep crossed it, so a softening joint bends the
peak. Where physics fixes the modal constant's phase (base and force references) the
quadrature of the measured ratio is read: the phase resonance at the amplitude the peak
had, i.e. the equivalent-linear (harmonic-balance) frequency at the run's level for a
slow sweep (measured within 0.2% on the Table 3.2 joint up to eta ~5). The fitted pole
and damping of a bent peak are not that (off by up to ~1% and tens of % on that joint;
the fit residual shows it, flag 'frf_misfit' in `jointcal.measure.modal`); a voltage reference
has only the pole, and its bent peak is read by ``pair_backbone``: lines of equal |X| below and
above the peak see the same frozen FRF, and each pair gives its pole without the modal constant
(``backbone_at_peak``: at the peak's amplitude). A fast chirp never builds the steady-state
amplitude, so it shows the structure at a smaller one.

Reference kinds (`jointcal.io.contract.REFERENCE`): base acceleration (g; the ratio is
the relative displacement z over the base acceleration, modal constant -G in/g),
force (lbf; receptance x/F) and amplifier voltage (V; x/V is the rig's FRF, the shaker
included: only its phase and ratios carry information, no damping can be taken from an
absolute force).
"""
from __future__ import annotations

from dataclasses import asdict

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import signal
from scipy.ndimage import uniform_filter1d

from ..units import G
from .modefit import ModeFit, basis, fit_mode, frf_flags, project, quadrature_ok, zeta_at_quadrature

__all__ = ["ModeFit", "h1_estimate", "zeta_at_quadrature", "displacement_ratio", "fit_mode", "record_frf",
           "frf_table", "quadrature_ok", "frf_flags", "MODAL_PHASE"]


def h1_estimate(ref: NDArray, resp: NDArray, fs: float, *, n_band: int = 5, pad: int = 4) -> pd.DataFrame:
    """Whole-record H1 of resp / ref, with band-averaged H2 and coherence.

    Parameters
    ----------
    ref, resp : ndarray, shape (n,)
        Reference (any unit) and response channels, sampled at `fs`; NaN samples
        count as zero (flag the run elsewhere).
    fs : float
        Sample rate, Hz.
    n_band : int
        Lines averaged (moving mean) for the diagnostic H2 and coherence.
    pad : int
        Zero-padding factor (FFT length >= pad * n): interpolated lines for the fit.

    Returns
    -------
    DataFrame, one row per line from 0 to fs/2
        freq_hz; h1_re, h1_im (resp unit / ref unit, whole record); h1s_re, h1s_im,
        h2_re, h2_im (band-averaged); coherence (0..1, band-averaged).
    """
    x = np.nan_to_num(np.asarray(ref, float))
    y = np.nan_to_num(np.asarray(resp, float))
    x, y = x - np.median(x), y - np.median(y)
    n = x.size
    nfft = 1 << int(np.ceil(np.log2(pad * n)))
    kw = dict(fs=fs, window="boxcar", nperseg=n, noverlap=0, nfft=nfft, detrend=False)
    f, pxy = signal.csd(x, y, **kw)  # conj(X) Y
    _, pxx = signal.welch(x, **kw)
    _, pyy = signal.welch(y, **kw)
    h1 = pxy / np.where(pxx > 0, pxx, np.inf)
    w = max(1, int(n_band)) * (nfft // n)  # n_band independent lines (padding interpolates)
    sxy = uniform_filter1d(pxy.real, w) + 1j * uniform_filter1d(pxy.imag, w)
    sxx, syy = uniform_filter1d(pxx, w), uniform_filter1d(pyy, w)
    h1s = sxy / np.where(sxx > 0, sxx, np.inf)
    h2 = syy / np.where(np.abs(sxy) > 0, np.conj(sxy), np.inf)
    coh = np.abs(sxy) ** 2 / np.where(sxx * syy > 0, sxx * syy, np.inf)
    return pd.DataFrame(dict(freq_hz=f, h1_re=h1.real, h1_im=h1.imag, h1s_re=h1s.real, h1s_im=h1s.imag,
                             h2_re=h2.real, h2_im=h2.imag, coherence=np.clip(coh, 0.0, 1.0)))


def displacement_ratio(f: NDArray, h_accel: NDArray, kind: str) -> NDArray:
    """The displacement ratio fitted, from the acceleration FRF.

    Parameters
    ----------
    f : ndarray, Hz;  h_accel : complex ndarray
        Response acceleration (g) over the reference (g, lbf or V).
    kind : {'base', 'force', 'voltage'}
        Reference kind. Base: relative displacement over base acceleration,
        z / a_b = -(H - 1) / w^2 (in/g); otherwise x / ref = -H G / w^2 (in/lbf, in/V).
    """
    w2 = (2 * np.pi * np.asarray(f, float)) ** 2
    w2 = np.where(w2 > 0, w2, np.inf)
    return -(h_accel - 1.0) * G / w2 if kind == "base" else -h_accel * G / w2


MODAL_PHASE = {"base": np.pi, "force": 0.0, "voltage": None}  # phase of the modal constant, rad


def record_frf(ref: NDArray, resp_g: NDArray, fs: float, kind: str, f_band: tuple[float, float], *,
               span: float = 2.0, f_guess: float | None = None, n_band: int = 5):
    """A run's whole-record FRF and the fit of its resonance.

    Parameters
    ----------
    ref : ndarray, shape (n,)
        Reference channel: base acceleration (g), force (lbf) or drive voltage (V).
    resp_g : ndarray, shape (n,)
        Response acceleration, g.
    fs : float
        Sample rate, Hz.
    kind : {'base', 'force', 'voltage'}
        Reference kind.
    f_band : (lo, hi), Hz
        The driven band.

    Returns
    -------
    table : DataFrame
        `h1_estimate`'s columns restricted to f_band, plus x_re, x_im (the
        displacement ratio fitted; in/g, in/lbf or in/V) and fit_re, fit_im (the fitted
        model on the fitted lines, NaN elsewhere).
    fit : ModeFit
    """
    tab = h1_estimate(ref, resp_g, fs, n_band=n_band)
    f = tab["freq_hz"].to_numpy()
    keep = (f >= f_band[0]) & (f <= f_band[1])
    tab = tab[keep].reset_index(drop=True)
    f = f[keep]
    X = displacement_ratio(f, (tab["h1_re"] + 1j * tab["h1_im"]).to_numpy(), kind)
    fit = fit_mode(f, X, f_band, span=span, f_guess=f_guess, modal_phase=MODAL_PHASE[kind],
                   coherence=tab["coherence"].to_numpy())
    y = np.nan_to_num(np.asarray(resp_g, float))
    y = y - np.median(y)
    tail = y[-max(8, min(y.size // 100, int(10 * fs / f_band[0]))):]  # the last 10 cycles (at most 1%)
    trunc = float(np.sqrt(np.mean(tail**2)) / max(np.max(np.abs(y)), 1e-300))
    fit = ModeFit(**{**asdict(fit), "truncated": trunc})
    sel = (f >= fit.f_lo_hz) & (f <= fit.f_hi_hz)
    w = 2 * np.pi * f
    coef, _ = project(w[sel], X[sel], 2 * np.pi * fit.f_n_hz, fit.zeta)
    model = np.full(f.size, np.nan, complex)
    model[sel] = basis(w[sel], 2 * np.pi * fit.f_n_hz, fit.zeta) @ coef
    tab = tab.assign(x_re=X.real, x_im=X.imag, fit_re=model.real, fit_im=model.imag)
    return tab, fit


def frf_table(tab: pd.DataFrame, run_id: str) -> pd.DataFrame:
    """`record_frf`'s table with the run id in front (tidy: one row per run and line)."""
    return tab.assign(run_id=run_id)[["run_id", *tab.columns]]
