"""A single-mode rational fit of an FRF peak, its quadrature and the damping read there.

``X(w) = A / (w_n^2 - w^2 + 2 i zeta w_n w) + R_0 + R_2 / w^2`` on the peak region of a
displacement ratio (`jointcal.measure.frf.displacement_ratio`), with complex A, R_0, R_2
(docs/physics.md, "Linear FRF"): w_n and zeta by least squares, the linear terms by variable
projection. Public names are re-exported by `jointcal.measure.frf`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import signal
from scipy.optimize import least_squares

from .peaks import anchored_phase, half_power_lines, phase_crossing

__all__ = ["ModeFit", "fit_mode", "zeta_at_quadrature", "quadrature_ok", "frf_flags", "basis", "project"]


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


def basis(w: NDArray, wn: float, zeta: float) -> NDArray:
    return np.stack([1.0 / (wn**2 - w**2 + 2j * zeta * wn * w), np.ones_like(w, complex), 1.0 / w**2], axis=1)


def project(w: NDArray, X: NDArray, wn: float, zeta: float):
    """Linear terms (A, R_0, R_2) by least squares for given w_n, zeta; returns (coef, misfit)."""
    B = basis(w, wn, zeta)
    s = np.abs(B).max(axis=0)
    coef, *_ = np.linalg.lstsq(B / s, X, rcond=None)
    return coef / s, X - B @ (coef / s)


def _half_power_zeta(f: NDArray, a: NDArray, ip: int) -> float:
    """Damping ratio from the half-power width of |X| around line ip, to the nearest lines (a rough start)."""
    i, j = half_power_lines(a, ip)
    f_lo = f[i] if i is not None else f[0]
    f_hi = f[j] if j is not None else f[-1]
    return float(np.clip((f_hi - f_lo) / (2 * f[ip]), 1e-4, 0.3))


def fit_mode(f: NDArray, X: NDArray, f_band: tuple[float, float], *, span: float = 2.0,
             f_guess: float | None = None, modal_phase: float | None = None,
             coherence: NDArray | None = None) -> ModeFit:
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
    coherence : ndarray, optional
        The band-averaged coherence on the lines f. Where given, the peak is the largest
        among those with coherence >= 0.5 (the drive's share of the response at least the
        noise's), when any has: noise divided by w^2 makes peaks of a displacement ratio
        toward 0 Hz (2% noise on a real 18 Hz beam record put them above the mode's, at
        coherence < 0.35 against the mode's 0.56-0.67).

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
        coherent = None if coherence is None else np.asarray(coherence)[inb][peaks] >= 0.5
        if coherent is not None and coherent.any():
            peaks = peaks[coherent]
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
            r = project(w, Xs / scale, np.exp(p[0]), np.exp(p[1]))[1]
            return np.concatenate([r.real, r.imag])

        lw = np.log(2 * np.pi * fn)
        sol = least_squares(misfit, [lw, np.log(zeta)], x_scale=[1e-3, 0.1], method="trf",
                            bounds=([lw - 0.2, np.log(1e-4)], [lw + 0.2, np.log(0.5)]))
        fn_new, zeta = float(np.exp(sol.x[0]) / (2 * np.pi)), float(np.exp(sol.x[1]))
        done = abs(fn_new / fn - 1) < 1e-6
        fn = fn_new
        if done:
            break
    coef, r = project(w, Xs, 2 * np.pi * fn, zeta)
    if modal_phase is None:  # rotate by the fitted modal constant, residual terms removed
        f_q, x_q = _quadrature(f[sel], (Xs - coef[1] - coef[2] / w**2) / coef[0], fn)
    else:  # the measured ratio itself: the phase resonance at the amplitude the peak had
        f_q, x_q = _quadrature(f[sel], Xs * np.exp(-1j * modal_phase) / np.abs(coef[0]), fn)
    return ModeFit(f_n_hz=fn, zeta=zeta, residual=float(np.linalg.norm(r) / scale), n_lines=int(sel.size),
                   f_lo_hz=float(f[sel].min()), f_hi_hz=float(f[sel].max()), f_quad_hz=f_q, x_quad=x_q,
                   modal_constant=float(np.abs(coef[0])), truncated=float("nan"))


def _quadrature(f: NDArray, Y: NDArray, fn: float) -> tuple[float, float]:
    """Frequency (Hz) where arg Y crosses -90 deg nearest fn, and |Y| there (interpolated)."""
    cross = phase_crossing(f, anchored_phase(Y, -np.pi / 2), -np.pi / 2, fn)
    if cross is None:
        return float("nan"), float("nan")
    i, u = cross
    return float(f[i] + u * (f[i + 1] - f[i])), float(abs(Y[i]) + u * (abs(Y[i + 1]) - abs(Y[i])))


def zeta_at_quadrature(fit: ModeFit) -> float:
    """Phase-resonance damping from the FRF, 1 / (2 w_q^2 x_quad): one amplitude, no bandwidth.

    X is divided by the fitted modal constant |A|; multiply by |A_known| / |A| where
    physics fixes it (G in/g for a single-DOF z / a_base). For a nonlinear structure
    the energy-balance damping at the peak's amplitude.
    """
    return float(1.0 / (2.0 * (2 * np.pi * fit.f_quad_hz) ** 2 * fit.x_quad))


def quadrature_ok(fit: ModeFit | None) -> bool:
    """True when the fit's quadrature lies within one half-power half-width of its pole (a read-out to trust)."""
    return bool(fit is not None and np.isfinite(fit.f_quad_hz)
                and abs(fit.f_quad_hz - fit.f_n_hz) <= fit.zeta * fit.f_n_hz)


def frf_flags(fit: ModeFit, flags: list[str], frf_misfit: float) -> None:
    """Append 'frf_truncated' (the response rings past the record's end) and 'frf_misfit' (not one mode) to flags."""
    if fit.truncated > 0.01:
        flags.append("frf_truncated")
    if fit.residual > frf_misfit:
        flags.append("frf_misfit")
