"""Steady-state read-out of dwells (stepped sines): one FRF point per run, a level's points give its mode.

A dwell drives the structure at one frequency until its transient has died out. Read at steady
state, it gives one point of the FRF at the amplitude it reached; a level's dwells at several
frequencies give the steady-state FRF near the mode, its phase resonance and its damping.

The read-out, in the order data flows:

1. **The steady part** (`dwell_point`): the drive's held part (up to its last sample within
   `HELD` of its plateau, the median of its largest sample per period: a ramp-down, a cut and a
   ring-down may follow), of which the last half is read. Over it the response and the reference
   are each fitted by least squares as ``c + Re(Z exp(i w t))`` at the dwell frequency over whole
   cycles (a lock-in: the joint's harmonics are orthogonal to it), giving ``H = Z_resp / Z_ref``
   (g per reference unit), the displacement ratio ``X`` (`jointcal.measure.frf.displacement_ratio`:
   ``-H G / w^2``; base-driven the relative displacement, ``-(H - 1) G / w^2``) and the displacement
   amplitude ``q_in = |X Z_ref|`` (in). ``H`` over the read part's first and second halves differs
   by more than `TRANSIENT` of ``|H|`` where the transient has not died out: flagged
   ``dwell_transient`` (a ratio, so that a controller's slow amplitude ripple, which moves both
   channels, is no transient).
2. **The level's mode** (`dwell_mode`): the points' displacement ratios ``X_i`` are fitted by one
   mode whose stiffness and damping follow the amplitude reached,
   ``A / X_i = wn^2(q_i) - w_i^2 + i w_i c(q_i)``, with ``wn^2`` and ``c`` affine in ``q_i`` and a
   complex modal constant A (linear in the unknowns: Levy's equation-error form of
   `jointcal.measure.modefit`'s single-mode model; the amplitude terms only with four points or
   more). Base-driven, A is -G exactly (a single mode's relative displacement per base
   acceleration) and is not fitted: on the Ministack at 2 g, five dwells across the bent peak fit
   A 8% off and the points' f by 0.5%. Every point then gives its natural frequency at its
   amplitude, ``wn_i^2 = w_i^2 + Re(A / X_i)`` (first harmonic balance: exact whatever the dwell's
   frequency), and its damping ``zeta_i = Im(A / X_i) / (2 wn_i w_i)`` (exact for viscous damping;
   a joint's hysteresis, rate independent, reads wn_i / w_i of it off resonance: docs/physics.md
   section 8).
3. **Phase resonance** (quadrature): where ``Re(A / X)`` changes sign between two points (the
   response 90 degrees behind the reference, A's own phase removed), by linear interpolation in
   ``w^2``; ``zeta`` and ``q_in`` there likewise. Flagged ``no_quadrature`` when the points do not
   straddle it (then the point nearest to it is given).

Checked against a linear mode's closed-form FRF and the exact Iwan simulator's steady states held
against first-harmonic balance at the amplitude reached (tests/measure/test_dwell.py).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import maximum_filter1d

from ..spectral import drive_end
from .frf import displacement_ratio

__all__ = ["dwell_point", "dwell_mode", "TRANSIENT", "HELD"]

TRANSIENT = 0.005  # the read part's halves differ by more than this share of the amplitude: still transient
HELD = 0.02  # the dwell ends where the drive's envelope last lies within this share of its plateau


def _lockin(x: NDArray, fs: float, f_hz: float) -> complex:
    """Z of ``c + Re(Z exp(i w t))`` fitted to `x` over its whole cycles of `f_hz` (t from x's first sample)."""
    n = int(np.floor(x.size * f_hz / fs) * fs / f_hz)  # whole cycles
    t = np.arange(n) / fs
    w = 2 * np.pi * f_hz
    B = np.stack([np.ones(n), np.cos(w * t), np.sin(w * t)], axis=1)
    c = np.linalg.lstsq(B, np.nan_to_num(x[:n]), rcond=None)[0]
    return complex(c[1], -c[2])


def dwell_point(response_g: NDArray, reference: NDArray, fs: float, f_hz: float, kind: str = "force") -> dict:
    """The steady amplitude and phase of one dwell's response relative to its reference.

    Parameters
    ----------
    response_g : ndarray, shape (n,)
        The response's acceleration (g).
    reference : ndarray, shape (n,)
        The reference (base g, force lbf or drive V), a sine at `f_hz` that may be cut to zero.
    fs, f_hz : float
        Sample rate and the dwell's frequency (Hz).
    kind : {'base', 'force', 'voltage'}, optional
        The reference's kind (base: the response is the absolute acceleration).

    Returns
    -------
    dict
        ``f_hz``; ``ratio`` (complex, response g per reference unit, the response's phase relative
        to the reference's); ``X`` (complex, in per reference unit), the displacement ratio;
        ``ref_amp`` (reference unit) and ``resp_amp_g`` (g), the steady amplitudes; ``q_in`` (in),
        the displacement amplitude (base-driven: relative to the base); ``t0_s``, ``t1_s`` (s), the
        read part; ``change``, the relative difference of its halves' ratios; ``flags`` (list:
        ``dwell_transient``).
    """
    ref = np.nan_to_num(np.asarray(reference, float))
    resp = np.asarray(response_g, float)
    d = np.abs(ref - np.median(ref))
    a = maximum_filter1d(d, max(int(round(fs / f_hz)), 1))  # the drive's envelope: its largest sample per period
    plateau = np.median(a[a > 0.5 * a.max()]) if a.max() > 0 else 0.0
    end = int(np.flatnonzero(d >= (1 - HELD) * plateau)[-1]) + 1 if plateau > 0 else ref.size  # its last peak
    # a reference that stays live after the cut (a force gauge on a shaker left attached: the armature's reaction,
    # at first above the dwell's force) holds its level past the cut; the response's steady state ends there
    cut = drive_end(fs, ref - np.median(ref), np.nan_to_num(resp)) if plateau > 0 else None
    end = min(end, cut) if cut is not None else end
    i0 = end // 2
    z_ref, z_resp = _lockin(ref[i0:end], fs, f_hz), _lockin(resp[i0:end], fs, f_hz)
    half = (end - i0) // 2
    first, second = ((_lockin(resp[a:b], fs, f_hz) / _lockin(ref[a:b], fs, f_hz))
                     for a, b in ((i0, i0 + half), (i0 + half, end)))
    H = z_resp / z_ref
    change = abs(second - first) / max(abs(H), 1e-300)
    X = complex(displacement_ratio(np.array([f_hz]), np.array([H]), kind)[0])
    return {"f_hz": float(f_hz), "ratio": H, "X": X, "ref_amp": abs(z_ref), "resp_amp_g": abs(z_resp),
            "q_in": abs(X * z_ref), "t0_s": i0 / fs, "t1_s": end / fs, "change": float(change),
            "flags": ["dwell_transient"] if change > TRANSIENT else []}


def dwell_mode(f_hz: NDArray, X: NDArray, q_in: NDArray, A: complex | None = None) -> dict:
    """One level's dwells: the mode at the amplitude reached, its phase resonance and damping.

    Parameters
    ----------
    f_hz : ndarray, shape (k,)
        The dwells' frequencies (Hz), k >= 3.
    X : ndarray of complex, shape (k,)
        Their displacement ratios (in per reference unit, `dwell_point`'s ``X``).
    q_in : ndarray, shape (k,)
        The displacement amplitude each reached (in).
    A : complex, optional
        The modal constant when the physics fixes it: base-driven, the relative displacement per base
        acceleration has ``A = -G`` (in/s^2 per g) whatever the mass. Fitted when None.

    Returns
    -------
    dict
        ``f_hz``, ``zeta``, ``q_in``: at phase resonance; ``points``: per dwell (in the order given)
        ``(q_in, f_n_hz, zeta)``, its natural frequency and damping at its amplitude; ``A`` (complex,
        in/s^2 per reference unit), the modal constant; ``residual``, the fit's relative rms
        equation error; ``flags`` (``no_quadrature``, ``few_points``).
    """
    f = np.asarray(f_hz, float)
    order = np.argsort(f)
    f, q = f[order], np.asarray(q_in, float)[order]
    w = 2 * np.pi * f
    X = np.asarray(X, complex)[order]
    flags = [] if f.size >= 3 else ["few_points"]
    qs = q / q.max()
    # A / X = a0 + a1 qs - w^2 + i w (b0 + b1 qs)  <=>  X (a0 + a1 qs) + i w X (b0 + b1 qs) - A = w^2 X
    cols = [X, 1j * w * X, -np.ones_like(X), -1j * np.ones_like(X)]
    if f.size >= 4 and np.ptp(qs) > 1e-6:
        cols[2:2] = [X * qs, 1j * w * X * qs]
    M = np.stack(cols, axis=1)
    rhs = w**2 * X
    scale = np.abs(M).max(axis=0)
    sol = np.linalg.lstsq(np.vstack([(M / scale).real, (M / scale).imag]),
                          np.concatenate([rhs.real, rhs.imag]), rcond=None)[0] / scale
    A = complex(sol[-2], sol[-1]) if A is None else complex(A)
    residual = float(np.linalg.norm(M @ sol - rhs) / np.linalg.norm(rhs))
    Y = A / X
    wn = np.sqrt(np.maximum(w**2 + Y.real, 0.0))
    zeta = Y.imag / (2 * wn * w)
    h = Y.real  # wn(q)^2 - w^2: positive below phase resonance
    k = np.flatnonzero((h[:-1] > 0) & (h[1:] <= 0))
    if k.size:
        i = int(k[0])
        s = h[i] / (h[i] - h[i + 1])  # linear in w^2
        w2 = w[i]**2 + s * (w[i + 1]**2 - w[i]**2)
        at = lambda v: v[i] + s * (v[i + 1] - v[i])  # noqa: E731
        fq, zq, qq = np.sqrt(w2) / (2 * np.pi), at(Y.imag) / (2 * w2), at(q)
    else:
        i = int(np.argmin(np.abs(h)))
        flags.append("no_quadrature")
        fq, zq, qq = wn[i] / (2 * np.pi), zeta[i], q[i]
    back = np.argsort(order)
    pts = [(float(q[j]), float(wn[j] / (2 * np.pi)), float(zeta[j])) for j in back]
    return {"f_hz": float(fq), "zeta": float(zq), "q_in": float(qq), "points": pts, "A": A,
            "residual": residual, "flags": flags}
