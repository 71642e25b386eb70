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
* ``pair_backbone``: a voltage reference's bent peak, pole by pole over the amplitudes the
  peak region spans (see below).
* ``fit_mode``: resonance and damping from a single-degree-of-freedom rational fit
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
the fit residual shows it, flag 'frf_misfit' in `jointcal.modal`); a voltage reference
has only the pole, and its bent peak is read by ``pair_backbone``: lines of equal |X| below and
above the peak see the same frozen FRF, and each pair gives its pole without the modal constant
(``backbone_at_peak``: at the peak's amplitude). A fast chirp never builds the steady-state amplitude, so it shows the
structure at a smaller one.

Reference kinds (`jointcal._contract.REFERENCE`): base acceleration (g; the ratio is
the relative displacement z over the base acceleration, modal constant -G in/g),
force (lbf; receptance x/F) and amplifier voltage (V; x/V is the rig's FRF, the shaker
included: only its phase and ratios carry information, no damping can be taken from an
absolute force).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import signal
from scipy.ndimage import uniform_filter1d
from scipy.optimize import brentq, least_squares

from .units import G

__all__ = ["ModeFit", "h1_estimate", "zeta_at_quadrature", "displacement_ratio", "fit_mode", "pair_backbone",
           "backbone_at_peak", "record_frf", "frf_table"]


@dataclass(frozen=True)
class ModeFit:
    """A single-mode fit of an FRF peak.

    f_n_hz : natural frequency |lambda| / 2 pi (Hz); for a real modal constant the
        quadrature (phase resonance) frequency.
    zeta : damping ratio -Re(lambda) / |lambda|.
    residual : relative RMS misfit over the fitted lines, ||X - fit|| / ||X||.
    n_lines : number of frequency lines fitted.
    f_lo_hz, f_hi_hz : the fitted band (Hz).
    f_quad_hz : quadrature frequency (Hz): where the measured ratio, less the fitted
        residual terms and divided by the fitted modal constant, is 90 deg behind; for a
        linear structure f_n_hz, for a nonlinear one the phase resonance at the peak
        amplitude (the harmonic-balance frequency at the run's level).
    x_quad : |X - residuals| / |A| at f_quad_hz (s^2): 1 / (2 zeta w_n^2) for a single
        mode, so the phase-resonance damping is 1 / (2 w^2 x_quad) (`zeta_at_quadrature`).
    modal_constant : |A| (unit of X times rad^2/s^2), the fitted modal constant.
    truncated : the response had not died out at the record's end (ratio of the
        response's RMS over the record's last 10 cycles of the band's lowest frequency,
        at most its last 1%, to its peak; > 0.01 leaks).
    """

    f_n_hz: float
    zeta: float
    residual: float
    n_lines: int
    f_lo_hz: float
    f_hi_hz: float
    f_quad_hz: float
    x_quad: float
    modal_constant: float
    truncated: float


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


def _basis(w: NDArray, wn: float, zeta: float) -> NDArray:
    return np.stack([1.0 / (wn**2 - w**2 + 2j * zeta * wn * w), np.ones_like(w, complex), 1.0 / w**2], axis=1)


def _project(w: NDArray, X: NDArray, wn: float, zeta: float):
    """Linear terms (A, R_0, R_2) by least squares for given w_n, zeta; returns (coef, misfit)."""
    B = _basis(w, wn, zeta)
    s = np.abs(B).max(axis=0)
    coef, *_ = np.linalg.lstsq(B / s, X, rcond=None)
    return coef / s, X - B @ (coef / s)


def _half_power_zeta(f: NDArray, a: NDArray, ip: int) -> float:
    """Damping ratio from the half-power width of |X| around line ip (a rough start)."""
    lvl = a[ip] / np.sqrt(2)
    lo = np.flatnonzero(a[:ip] < lvl)
    hi = np.flatnonzero(a[ip:] < lvl)
    f_lo = f[lo[-1]] if lo.size else f[0]
    f_hi = f[ip + hi[0]] if hi.size else f[-1]
    return float(np.clip((f_hi - f_lo) / (2 * f[ip]), 1e-4, 0.3))


def fit_mode(f: NDArray, X: NDArray, f_band: tuple[float, float], *, span: float = 2.0,
             f_guess: float | None = None, modal_phase: float | None = None) -> ModeFit:
    """Single-mode rational fit of the strongest interior peak of X in f_band (or the one at f_guess).

    Parameters
    ----------
    f : ndarray, Hz;  X : complex ndarray
        Displacement ratio (see `displacement_ratio`) on the lines f.
    f_band : (lo, hi), Hz
        Where to look for the peak (the driven band).
    span : float
        Half-width of the fitted band in half-power bandwidths: lines within
        f_n (1 +- span zeta). 2 keeps the peak region (|X| > 0.45 of the peak), where
        the single mode dominates and a nonlinear structure's amplitude is near its
        peak value; the residual terms take the rest.
    f_guess : float, optional
        Start near this frequency (Hz) instead of the largest interior peak of |X| in the band.
    modal_phase : float, optional
        The modal constant's phase when physics fixes it (rad): pi for z / a_base, 0 for
        x / F. The quadrature is then read on the measured ratio itself, which for a
        nonlinear structure is the phase resonance at the peak's amplitude (the fitted
        pole and residuals absorb the peak's amplitude-dependent distortion: measured
        on the Table 3.2 joint at eta 1-5, the fit's w_n is off the harmonic balance at
        the reached amplitude by up to 1.3%, the measured ratio's quadrature by < 0.2%).
        None (a voltage reference): rotate by the fitted modal constant.

    Returns
    -------
    ModeFit (truncated = NaN; `record_frf` fills it).
    """
    lo, hi = f_band
    inb = np.flatnonzero((f >= lo) & (f <= hi) & np.isfinite(X))
    if inb.size < 8:
        raise ValueError(f"fewer than 8 FRF lines in {lo:g}-{hi:g} Hz; record a longer sweep.")
    a = np.abs(X[inb])
    if f_guess is None:  # the largest interior peak (a displacement ratio grows without bound toward 0 Hz)
        peaks, _ = signal.find_peaks(a)
        ip = int(peaks[np.argmax(a[peaks])]) if peaks.size else int(np.argmax(a))
    else:
        ip = int(np.argmin(np.abs(f[inb] - f_guess)))
    fn, zeta = float(f[inb][ip]), _half_power_zeta(f[inb], a, ip)
    for _ in range(3):  # the fitted band follows the fitted mode
        sel = inb[np.abs(f[inb] - fn) <= span * max(zeta, 2 * (f[1] - f[0]) / fn) * fn]
        if sel.size < 6:
            sel = inb[np.argsort(np.abs(f[inb] - fn))[:6]]
        w, Xs = 2 * np.pi * f[sel], X[sel]
        scale = np.linalg.norm(Xs)

        def misfit(p):
            r = _project(w, Xs / scale, np.exp(p[0]), np.exp(p[1]))[1]
            return np.concatenate([r.real, r.imag])

        lw = np.log(2 * np.pi * fn)
        sol = least_squares(misfit, [lw, np.log(zeta)], x_scale=[1e-3, 0.1], method="trf",
                            bounds=([lw - 0.2, np.log(1e-4)], [lw + 0.2, np.log(0.5)]))
        fn_new, zeta = float(np.exp(sol.x[0]) / (2 * np.pi)), float(np.exp(sol.x[1]))
        done = abs(fn_new / fn - 1) < 1e-6
        fn = fn_new
        if done:
            break
    coef, r = _project(w, Xs, 2 * np.pi * fn, zeta)
    if modal_phase is None:  # rotate by the fitted modal constant, residual terms removed
        f_q, x_q = _quadrature(f[sel], (Xs - coef[1] - coef[2] / w**2) / coef[0], fn)
    else:  # the measured ratio itself: the phase resonance at the amplitude the peak had
        f_q, x_q = _quadrature(f[sel], Xs * np.exp(-1j * modal_phase) / np.abs(coef[0]), fn)
    return ModeFit(f_n_hz=fn, zeta=zeta, residual=float(np.linalg.norm(r) / scale), n_lines=int(sel.size),
                   f_lo_hz=float(f[sel].min()), f_hi_hz=float(f[sel].max()), f_quad_hz=f_q, x_quad=x_q,
                   modal_constant=float(np.abs(coef[0])), truncated=float("nan"))


def _quadrature(f: NDArray, Y: NDArray, fn: float) -> tuple[float, float]:
    """Frequency (Hz) where arg Y crosses -90 deg nearest fn, and |Y| there (interpolated)."""
    ph = np.unwrap(np.angle(Y))
    ph += 2 * np.pi * np.round((-np.pi / 2 - np.median(ph)) / (2 * np.pi))
    d = ph + np.pi / 2
    c = np.flatnonzero(d[:-1] * d[1:] <= 0)
    if not c.size:
        return float("nan"), float("nan")
    i = c[np.argmin(np.abs(f[c] - fn))]
    u = d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else 0.0
    return float(f[i] + u * (f[i + 1] - f[i])), float(abs(Y[i]) + u * (abs(Y[i + 1]) - abs(Y[i])))


def zeta_at_quadrature(fit: ModeFit) -> float:
    """Phase-resonance damping from the FRF, 1 / (2 w_q^2 x_quad): one amplitude, no bandwidth.

    X is divided by the fitted modal constant |A|; multiply by |A_known| / |A| where
    physics fixes it (G in/g for a single-DOF z / a_base). For a nonlinear structure
    the energy-balance damping at the peak's amplitude.
    """
    return float(1.0 / (2.0 * (2 * np.pi * fit.f_quad_hz) ** 2 * fit.x_quad))


def pair_backbone(f: NDArray, X: NDArray, levels: NDArray = np.linspace(0.5, 0.9, 17), *,
                  f_guess: float | None = None, near_frac: float = 0.1) -> pd.DataFrame:
    """Equivalent-linear frequency and damping at several amplitudes, from equal-amplitude line pairs.

    For a drive of constant amplitude (an amplifier's voltage) each line of a quasi-steady
    sweep's ratio X = x / ref is the equivalent-linear (first-harmonic) FRF frozen at the
    amplitude q the structure had there, and q is proportional to |X|. At a level s of the
    peak, the line w_1 below and w_2 above the peak with |X| = s |X|_peak see the SAME frozen
    FRF A / (Omega^2 - w^2 + i D w), so

        Omega^2 = (w_1^2 + w_2^2 + D^2) / 2                      (|X(w_1)| = |X(w_2)|)
        arg X(w_1) - arg X(w_2) = arg[(Omega^2 - w_2^2 + i D w_2) / (Omega^2 - w_1^2 + i D w_1)]

    which give Omega and D at that amplitude without the modal constant A (its phase cancels:
    an amplifier voltage's phase to the force is unknown). zeta = D / (2 Omega). For a linear
    structure every level gives the same exact pole; for a softening joint Omega falls and zeta
    grows towards the peak: the backbone over the amplitudes the peak region spans.

    Parameters
    ----------
    f : ndarray, Hz;  X : complex ndarray
        Displacement ratio on increasing lines (`displacement_ratio`), the peak region included.
    levels : ndarray
        Fractions s of the peak |X| (0 < s < 1) at which pairs are taken.
    f_guess : float, optional
        The largest |X| within f_guess (1 +- near_frac) (Hz) instead of the largest overall.

    Returns
    -------
    DataFrame, one row per level resolved
        level (s), f1_hz, f2_hz (the pair), f_hz (Omega / 2 pi), zeta. Levels whose pair
        leaves the lines, or whose phase difference no damping reproduces, are left out.

    Notes
    -----
    Assumes the modal constant constant across the pair and no other mode nearby (an
    amplifier's coil inductance turns A by -(L/R) / (1 + (w L/R)^2) rad per rad/s: about 1% of
    the phase difference on the synthetic Ministack rig), and quasi-steady lines: a sweep too
    fast for the nonlinear structure to follow (eta above ~5) breaks the line-amplitude map.
    """
    ok = np.isfinite(X)
    f, X = np.asarray(f, float)[ok], np.asarray(X)[ok]
    a = np.abs(X)
    near = np.ones(a.size, bool) if f_guess is None else np.abs(f / f_guess - 1) <= near_frac
    ip = int(np.flatnonzero(near)[np.argmax(a[near])]) if near.any() else int(np.argmax(a))
    s = a / a[ip]
    ph = np.unwrap(np.angle(X))
    rows = []
    for lv in np.atleast_1d(levels):
        lo, hi = np.flatnonzero(s[:ip] < lv), np.flatnonzero(s[ip:] < lv)
        if not (lo.size and hi.size):
            continue
        i, j = lo[-1], ip + hi[0] - 1  # crossings between lines i, i+1 (rising) and j, j+1 (falling)
        u, v = (lv - s[i]) / (s[i + 1] - s[i]), (lv - s[j]) / (s[j + 1] - s[j])
        f1, f2 = f[i] + u * (f[i + 1] - f[i]), f[j] + v * (f[j + 1] - f[j])
        dphi = (ph[i] + u * (ph[i + 1] - ph[i])) - (ph[j] + v * (ph[j + 1] - ph[j]))
        w1, w2 = 2 * np.pi * f1, 2 * np.pi * f2

        def gap(D):
            o2 = 0.5 * (w1**2 + w2**2 + D**2)
            return np.angle((o2 - w2**2 + 1j * D * w2) / (o2 - w1**2 + 1j * D * w1)) - dphi

        lo_d, hi_d = 1e-6 * w1, 2.0 * w1
        if not (w2 > w1 and gap(lo_d) * gap(hi_d) < 0):
            continue
        D = brentq(gap, lo_d, hi_d, xtol=1e-12 * w1)
        om = np.sqrt(0.5 * (w1**2 + w2**2 + D**2))
        rows.append(dict(level=float(lv), f1_hz=float(f1), f2_hz=float(f2), f_hz=float(om / (2 * np.pi)),
                         zeta=float(D / (2 * om))))
    return pd.DataFrame(rows, columns=["level", "f1_hz", "f2_hz", "f_hz", "zeta"])


def backbone_at_peak(bb: pd.DataFrame, *, min_levels: int = 5) -> tuple[float, float, float]:
    """The pair backbone extrapolated to the peak's amplitude (s = 1): frequency (Hz), zeta, spread.

    A straight line in s through the levels (least squares), evaluated at s = 1: the
    equivalent-linear pole at the amplitude of the peak, i.e. at the run's steady-state
    level for a slow sweep. spread: the RMS relative misfit of that line to the levels'
    frequencies (how far the backbone is from straight over 0.5-0.9 of the peak).
    NaNs when fewer than `min_levels` levels were resolved.
    """
    if len(bb) < min_levels:
        return float("nan"), float("nan"), float("nan")
    s = bb["level"].to_numpy()
    cf, cz = np.polyfit(s, bb["f_hz"], 1), np.polyfit(s, bb["zeta"], 1)
    spread = float(np.sqrt(np.mean((np.polyval(cf, s) / bb["f_hz"].to_numpy() - 1) ** 2)))
    return float(np.polyval(cf, 1.0)), float(np.polyval(cz, 1.0)), spread


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
    fit = fit_mode(f, X, f_band, span=span, f_guess=f_guess, modal_phase=MODAL_PHASE[kind])
    y = np.nan_to_num(np.asarray(resp_g, float))
    y = y - np.median(y)
    tail = y[-max(8, min(y.size // 100, int(10 * fs / f_band[0]))):]  # the last 10 cycles (at most 1%)
    trunc = float(np.sqrt(np.mean(tail**2)) / max(np.max(np.abs(y)), 1e-300))
    fit = ModeFit(**{**asdict(fit), "truncated": trunc})
    sel = (f >= fit.f_lo_hz) & (f <= fit.f_hi_hz)
    w = 2 * np.pi * f
    coef, _ = _project(w[sel], X[sel], 2 * np.pi * fit.f_n_hz, fit.zeta)
    model = np.full(f.size, np.nan, complex)
    model[sel] = _basis(w[sel], 2 * np.pi * fit.f_n_hz, fit.zeta) @ coef
    tab = tab.assign(x_re=X.real, x_im=X.imag, fit_re=model.real, fit_im=model.imag)
    return tab, fit


def frf_table(tab: pd.DataFrame, run_id: str) -> pd.DataFrame:
    """`record_frf`'s table with the run id in front (tidy: one row per run and line)."""
    return tab.assign(run_id=run_id)[["run_id", *tab.columns]]
