"""The structure's own backbone from a decay that a force still acts on: read through the measured force.

A force-referenced rig whose drive voltage is cut leaves the shaker attached: its armature, suspension and
coil go on pushing on the structure, the force gauge goes on reading that push, and the decay rings at the
coupled rig's pole, not the structure's (a 0.05 lbf armature on a 1 lbf, 100 Hz beam: 2.4% low). The gauge
measures the force the structure feels, so the structure's own dynamic stiffness follows from the two channels.

For one mode with modal constant A (1/m for a force at the driving point) and the joint linearised at the
amplitude of the moment (first-harmonic balance), the displacement x and the force F obey

    x'' + c'(q) x' + wn(q)^2 x = A F(t),      c' = 2 zeta wn.

Over a window of the decay both channels are one decaying oscillation at the same complex frequency
s = -sigma + i w (the rig's pole: the structure, the armature and the coil ring together), x = Re(X e^{st}),
F = Re(P e^{st}), so

    s^2 + c' s + wn^2 = A P / X = A / H(s),      H = X / P  (in/lbf)

and, with Y = A / H - s^2 (a complex number, 1/s^2),

    c' = Im(Y) / w,      wn^2 = Re(Y) + c' sigma,      zeta = c' / (2 wn).

With F = 0 (a free decay) Y = -s^2 and this is `jointcal.measure.ringdown`'s read-out: wn^2 = w^2 + sigma^2,
zeta = sigma / wn. The modes outside the band add their flexibility at the driving point, H = 1 / S_1 + R
(R the residual receptance, in/lbf), so `residual` is taken off H first; the structure's coordinate is then
x = X_measured - R P. A is what a dwell's or a sweep's force-referenced fit calls the modal constant
(`jointcal.measure.dwell.dwell_mode`, `jointcal.measure.sweepfit.SweepFit.modal_constant`): it must come
from the same campaign. Its error enters through the force's share only: |A P / X| is about m_a / m of
|s|^2 (the armature's mass over the mode's), so 1% in A moves wn by about m_a / (2 m) % and zeta by the
shaker's share of the coupled damping times 1%.

The damping is read as viscous at the window's frequency w. A joint's quadrature force is rate independent
(a hysteretic loss h: Im(m Y) = c w + h), so where w lies below wn (the rig's pole below the structure's)
the joint's share of zeta is read wn / w - 1 high (2.4% of that share on the beam above), the dashpot's
exactly (`docs/physics.md` section 8 says the same of a dwell off resonance).

The windows are `jointcal.measure.ringdown.ringdown_backbone`'s (its start, settle, window growth and noise
floor, from the response); each is read again here with both channels band-passed apart from the forced part
before the cut, and fitted on one basis: the response's damped sinusoid with its frequency and decay rate
drifting linearly over the window (`jointcal.measure._decay_window`), the force's amplitude and phase on the
same basis by linear least squares (`_pair_window`).

Checked against closed forms (tests/measure/test_forced_decay.py): a linear mode on a linear shaker
(armature, suspension, coil), whose coupled pole and whose structure are both known exactly, and the exact
Iwan beam on its shaker, held against the structure's first-harmonic balance.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import signal
from scipy.optimize import least_squares

from ..units import G
from ._decay_window import fit_window
from .ringdown import BAND, EXTEND, GROW, MISFIT_MAX, MIN_CYCLES, SPAN_MAX, TAIL, ZETA_SE_MAX, ringdown_backbone

__all__ = ["structure_pole", "forced_decay_backbone", "Receptance", "flank_receptance", "COLUMNS", "FLANK"]

FLANK = 0.15  # FRF lines below this share of the peak's |X|: the mode's flanks, its joint barely slipping

COLUMNS = ["t_s", "window_s", "q_in", "f_hz", "zeta", "zeta_se", "f_rig_hz", "zeta_rig", "force_share", "misfit", "flags"]


def structure_pole(s: ArrayLike, H: ArrayLike, modal_constant: complex,
                   residual: complex = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The structure's own natural frequency and damping from its receptance at a decay's complex frequency.

    Parameters
    ----------
    s : array_like of complex, shape (k,)
        The decay's complex frequency -sigma + i w per window, 1/s (w > 0).
    H : array_like of complex, shape (k,)
        The measured displacement over force at s, X / P (in/lbf).
    modal_constant : complex
        A, (in/s^2) per lbf: 1/m for a force at the driving point.
    residual : complex
        The other modes' receptance at the driving point near this one, in/lbf (0: none).

    Returns
    -------
    wn : ndarray, shape (k,)
        Natural frequency, rad/s: wn^2 = Re(Y) + c' sigma with Y = A / (H - R) - s^2, c' = Im(Y) / w.
    zeta : ndarray, shape (k,)
        Damping ratio c' / (2 wn) (viscous at w; see the module docstring for a joint's share).
    """
    s = np.asarray(s, complex)
    H = np.asarray(H, complex)
    if not np.all(s.imag > 0):
        raise ValueError(f"the decay's complex frequency must have a positive imaginary part (w > 0), got {s!r}.")
    Y = complex(modal_constant) / (H - complex(residual)) - s**2
    c = Y.imag / s.imag
    wn2 = Y.real - c * s.real
    wn = np.sqrt(np.where(wn2 > 0, wn2, np.nan))
    return wn, c / (2 * wn)


@dataclass(frozen=True)
class Receptance:
    """What a campaign measured of one mode at the driving point, to read its decays through the force.

    modal_constant : complex, (in/s^2) per lbf (1/m), e.g. a force-referenced sweep fit's.
    r0 : float, in/lbf, and r2 : float, in/lbf per (rad/s)^2: the other modes' receptance near the mode,
        R(w) = r0 + r2 w^2 (a stiffness line and its first mass correction).
    source : str, the run(s) it was measured on.
    """

    modal_constant: complex
    r0: float = 0.0
    r2: float = 0.0
    source: str = ""

    def residual(self, f_hz: float) -> float:
        """R at f_hz (Hz), in/lbf."""
        return float(self.r0 + self.r2 * (2 * np.pi * f_hz) ** 2)


def flank_receptance(f_hz: ArrayLike, X: ArrayLike, modal_constant: complex, *, flank: float = FLANK,
                     source: str = "") -> Receptance:
    """The other modes' receptance near a mode, from a force-referenced FRF's flanks, its modal constant known.

    On the lines where |X| is below `flank` of its peak (both sides of the mode, the joint at a small share
    of its peak amplitude: nearly linear) the FRF is fitted by
    ``X = A / (W - w^2 + i w C) + r0 + r2 w^2`` with A given and W, C (the mode there) and r0, r2 (real) fitted:
    W and C by least squares, r0 and r2 by variable projection. At the peak a bent, amplitude-dependent mode
    would take the residual terms into its own distortion (a single-mode fit of the whole peak of a jointed
    beam put them wrong in size and sign); on its flanks the mode is nearly the linear one and the known A
    fixes its size.

    Parameters
    ----------
    f_hz : array_like, shape (k,)
        FRF lines, Hz (a sweep's band; its edges, where the drive ramps, left out by the caller).
    X : array_like of complex, shape (k,)
        Displacement over force on those lines, in/lbf (`jointcal.measure.frf.displacement_ratio`).
    modal_constant : complex
        A, (in/s^2) per lbf.
    flank : float
        Lines below this share of the largest |X| are fitted.
    source : str
        Kept in the result.

    Returns
    -------
    Receptance
    """
    f = np.asarray(f_hz, float)
    X = np.asarray(X, complex)
    A = complex(modal_constant)
    ok = np.isfinite(f) & np.isfinite(X) & (f > 0)
    f, X = f[ok], X[ok]
    if f.size < 8 or not (np.isfinite(A) and A != 0):
        raise ValueError(f"the receptance needs 8 finite FRF lines and a finite, nonzero modal constant; got "
                         f"{f.size} lines and A = {modal_constant!r}.")
    ip = int(np.argmax(np.abs(X)))
    use = np.abs(X) < flank * np.abs(X[ip])
    if not (use[:ip].sum() >= 4 and use[ip:].sum() >= 4):
        raise ValueError(f"the FRF has fewer than 4 lines below {flank:g} of its peak on each side of it "
                         f"({f.min():g}-{f.max():g} Hz, peak at {f[ip]:g} Hz); sweep further past the mode.")
    w, Xu = 2 * np.pi * f[use], X[use]
    B = np.vstack([np.stack([np.ones_like(w), w**2], 1), np.zeros((w.size, 2))])
    scale = float(np.abs(Xu).max())
    w_pk = 2 * np.pi * f[ip]

    def fit(p):
        M = Xu - A / (p[0] * w_pk**2 - w**2 + 1j * w * p[1] * w_pk)
        y = np.concatenate([M.real, M.imag])
        c = np.linalg.lstsq(B, y, rcond=None)[0]
        return c, (y - B @ c) / scale

    half = 0.5 * abs(A) / (w_pk**2 * scale)  # the peak's half-width from its height: |X| ~ A / (w^2 2 zeta)
    p = least_squares(lambda p: fit(p)[1], [1.0, max(2 * half, 1e-4)], x_scale=[1e-3, 1e-3]).x
    r0, r2 = fit(p)[0]
    return Receptance(A, float(r0), float(r2), source)


def _basis(p: NDArray, t: NDArray) -> NDArray:
    w, sig, r, sd = p
    env = np.exp(-sig * t - 0.5 * sd * t * t)
    ph = w * t + 0.5 * r * t * t
    return np.column_stack([env * np.cos(ph), env * np.sin(ph)])


def _pair_window(t: NDArray, x: NDArray, F: NDArray, w0: float,
                 sig0: float) -> tuple[complex, complex, complex, float, float, float]:
    """One window of both channels on one basis: the response's damped sinusoid, frequency and decay rate drifting.

    Returns s = -sigma + i w at the window's centre (1/s), the phasors of x and F there (their units; the
    signal is Re(phasor e^{i w t}) near t = 0), the response's relative rms misfit, and per unit white-noise
    rms the standard errors of the response's decay rate (`fit_window`'s, 1/s) and of the force's phasor (sqrt
    of the trace of (B^T B)^-1).
    """
    w, sig, _, _, se_sig, _ = fit_window(t, x, w0, sig0)
    span = max(float(np.ptp(t)), 1.0 / w)
    scale = np.array([1.0 / span, 1.0 / span, 1.0 / span**2, 1.0 / span**2])  # a unit step moves the phase ~1 rad

    def misfit(u):
        B = _basis(u * scale, t)
        return x - B @ np.linalg.lstsq(B, x, rcond=None)[0]

    p = least_squares(misfit, np.array([w, sig, 0.0, 0.0]) / scale, method="lm").x * scale
    B = _basis(p, t)
    (ax, bx), (aF, bF) = np.linalg.lstsq(B, np.column_stack([x, F]), rcond=None)[0].T
    res = float(np.sqrt(np.mean(misfit(p / scale) ** 2)) / max(np.hypot(ax, bx) / np.sqrt(2), 1e-300))
    se = float(np.sqrt(np.trace(np.linalg.inv(B.T @ B))))
    return complex(-p[1], p[0]), complex(ax, -bx), complex(aF, -bF), res, se_sig, se


def _apart(x: NDArray, F: NDArray, i0: int, n: int, fs: float, f_hz: float) -> tuple[NDArray, NDArray]:
    """Both channels band-passed, each decay from `i0` on apart from the forced part before it.

    As `jointcal.measure.ringdown` does for the response: the decay's first `n` samples are fitted by the
    response's damped sinusoid (the force on its basis), continued `EXTEND` periods backwards, and the
    continuation and the decay band-passed together (twice: raw, then band-passed), so that the filter sees no
    forced part and no edge at the cut. Where that first window is not one damped sinusoid (other modes ring
    from the start) the whole records are band-passed.
    """
    sos = signal.butter(4, [f_hz * (1 - BAND), f_hz * (1 + BAND)], btype="bandpass", fs=fs, output="sos")
    x, F = x - np.median(x), F - np.median(F)
    y, g = signal.sosfiltfilt(sos, x), signal.sosfiltfilt(sos, F)
    if i0 + n > x.size:
        return y, g
    pad = int(round(EXTEND * fs / f_hz))
    tw = (np.arange(n) - (n - 1) / 2) / fs
    t_pad = (np.arange(-pad, 0) - (n - 1) / 2) / fs
    sx, sF = x, F
    for k in range(2):
        w, sig, _, misfit, _, _ = fit_window(tw, sx[i0:i0 + n], 2 * np.pi * f_hz)
        if k == 0 and misfit > MISFIT_MAX:
            return y, g
        B = _basis(np.array([w, sig, 0.0, 0.0]), tw)
        coef = np.linalg.lstsq(B, np.column_stack([sx[i0:i0 + n], sF[i0:i0 + n]]), rcond=None)[0]
        cont = _basis(np.array([w, sig, 0.0, 0.0]), t_pad) @ coef
        sx, sF = (np.concatenate([full[:i0], signal.sosfiltfilt(sos, np.concatenate([cont[:, j], raw[i0:]]))[pad:]])
                  for j, (full, raw) in enumerate(((y, x), (g, F))))
    return sx, sF


def forced_decay_backbone(response_g: ArrayLike, force_lbf: ArrayLike, fs: float, f_hz: float,
                          modal_constant: complex, *, residual: complex = 0.0, start: int | None = None,
                          min_cycles: float = MIN_CYCLES) -> pd.DataFrame:
    """The structure's frequency and damping along a decay that the shaker still pushes on, against its amplitude.

    Parameters
    ----------
    response_g : array_like, shape (n,)
        Response acceleration at the driving point, g (NaN samples count as zero).
    force_lbf : array_like, shape (n,)
        The force gauge between the shaker and the structure, lbf.
    fs : float
        Sample rate, Hz.
    f_hz : float
        The mode's approximate frequency, Hz (as `jointcal.measure.ringdown.ringdown_backbone`).
    modal_constant : complex
        A, (in/s^2) per lbf (1/m), measured in the same campaign (a sweep's or the dwells' fit).
    residual : complex
        The other modes' receptance at the driving point near the mode, in/lbf.
    start : int, optional
        First sample of the decay; default `jointcal.measure.ringdown.decay_start` from the response.
    min_cycles : float
        The shortest window, periods of the mode.

    Returns
    -------
    DataFrame
        One row per window of `ringdown_backbone` (its ``t_s``, ``window_s``, ``misfit`` and ``flags``):
        ``q_in`` (the structure's displacement amplitude at the window's centre, in: |X - R P|),
        ``f_hz`` and ``zeta`` (the structure's own, `structure_pole`; Hz), ``f_rig_hz`` and ``zeta_rig`` (the
        decay's own pole |s| / 2 pi and sigma / |s|: the coupled rig's), ``force_share`` (|A P / X| / |s|^2:
        how much of the decay the force carries; 0 for a free decay).
    """
    x = np.nan_to_num(np.asarray(response_g, float))
    F = np.nan_to_num(np.asarray(force_lbf, float))
    if x.shape != F.shape:
        raise ValueError(f"the response ({x.size} samples) and the force ({F.size}) must be one record's channels.")
    A = complex(modal_constant)
    if not (np.isfinite(A) and A != 0):
        raise ValueError(f"the modal constant must be a finite, nonzero number ((in/s^2) per lbf), got {modal_constant!r}.")
    win = ringdown_backbone(x, fs, f_hz, start=start, min_cycles=min_cycles)
    if win.empty:
        return pd.DataFrame(columns=COLUMNS)
    n = int(round(win["window_s"].iloc[0] * fs))
    lo = int(round(win["t_s"].iloc[0] * fs - (n - 1) / 2))  # the decay's first window: read from here on
    y, g = _apart(x, F, lo, n, fs, f_hz)
    tail = max(n, int(TAIL * y.size))  # the band-passed records' rms where the decay has died out: the noise
    noise_x, noise_F = (float(np.sqrt(np.mean(v[-tail:] ** 2))) for v in (y, g))
    per_sample = np.sqrt(fs / (4 * BAND * f_hz))  # one independent noise sample in fs / 2B (as ringdown's)
    rows, w0, sig0 = [], 2 * np.pi * f_hz, 0.0
    while lo + n <= y.size:
        row, s = _read(y, g, lo, n, fs, w0, sig0, A, complex(residual), noise_x * per_sample, noise_F * per_sample)
        good = np.isfinite(row["zeta"]) and row["zeta"] > 0 and s.real < 0 and 0.5 * w0 < s.imag < 1.5 * w0
        longer = int(n * GROW) + 1
        if good and row["zeta_se"] > ZETA_SE_MAX * row["zeta"] and -s.real * longer / fs <= SPAN_MAX \
                and lo + longer <= y.size:
            n = longer  # too short for the noise: the same start, a longer window
            continue
        if not (good and row["zeta_se"] <= ZETA_SE_MAX * row["zeta"]):
            if rows:
                rows[-1]["flags"] = "noise_floor"
            break
        rows.append(row)
        w0, sig0 = s.imag, -s.real
        lo += max(1, n // 2)
    return pd.DataFrame(rows, columns=COLUMNS)


def _read(y: NDArray, g: NDArray, lo: int, n: int, fs: float, w0: float, sig0: float, A: complex, R: complex,
          noise_x: float, noise_F: float) -> tuple[dict, complex]:
    """One window y[lo:lo + n], g[lo:lo + n] read: its row of `forced_decay_backbone` and its s (1/s).

    noise_x, noise_F: the channels' noise per independent sample (g, lbf)."""
    t = (np.arange(n) - (n - 1) / 2) / fs
    s, px, pF, res, se_sig, se_p = _pair_window(t, y[lo:lo + n], g[lo:lo + n], w0, sig0)
    X = px * G / s**2  # displacement, in
    wn, z = (v[0] for v in structure_pole(np.array([s]), np.array([X / pF]), A, R))
    share = abs(A * pF / X) / abs(s) ** 2
    # zeta's standard error: the decay rate's (c' holds 2 sigma) and the force phasor's (c' holds Im(A P / X) / w)
    se = np.hypot(se_sig * noise_x, share * abs(s) ** 2 * se_p * noise_F / max(abs(pF), 1e-300) / 2 / s.imag) / wn
    row = dict(t_s=(lo + (n - 1) / 2) / fs, window_s=n / fs, q_in=abs(X - R * pF), f_hz=wn / (2 * np.pi), zeta=z,
               zeta_se=float(se), f_rig_hz=abs(s) / (2 * np.pi), zeta_rig=-s.real / abs(s), force_share=share,
               misfit=res, flags="misfit" if res > MISFIT_MAX else "")
    return row, s
