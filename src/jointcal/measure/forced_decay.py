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
from the same campaign, as must R (`jointcal.measure.receptance`). Its error enters through the force's
share only: |A P / X| is about m_a / m of |s|^2 (the armature's mass over the mode's), so 1% in A moves wn
by about m_a / (2 m) % and zeta by the shaker's share of the coupled damping times 1%.

The damping is read as viscous at the window's frequency w. A joint's quadrature force is rate independent
(a hysteretic loss h: Im(m Y) = c w + h), so where w lies below wn (the rig's pole below the structure's)
the joint's share of zeta is read wn / w - 1 high (2.4% of that share on the beam above), the dashpot's
exactly (`docs/physics.md` section 8 says the same of a dwell off resonance).

The read-out, in the order data flows:

1. **Both channels apart** (`_apart`): band-passed as `jointcal.measure.ringdown` does the response, the decay
   after its own damped sinusoid continued backwards, what that sinusoid leaves of the first periods (other
   modes ringing from the cut) faded in; the first `SETTLE_LIVE` periods after the start are not read.
2. **Windows** (`_pair_window`): both channels as one decaying oscillation, a damped sinusoid whose frequency
   and decay rate drift linearly over the window (`jointcal.measure._decay_window`'s model), each channel with
   its own amplitude and phase; the frequency, rate and drifts fitted to both at once (the force's residual
   weighted by the channels' noise ratio), the amplitudes by variable projection: s, X and P at the window's
   centre. The force holds the decay rate as well as the response does, so this reads about 0.15 decade
   further down than the response alone. Windows grow and stop by `jointcal.measure.ringdown`'s rules and
   constants, the decay rate's standard error held within `ZETA_SE_LIVE` of the structure's zeta (smaller than
   the rig's): 0.8%, where the ring-down holds 1% (`ZETA_SE_MAX`), so that three standard errors and the
   joint's bias below (+0.6% at most on the virtual beam) stay within 3% (at 1%, 3.65% was read once in
   ~400 windows; 0.8% costs 0.1-0.2 decade).
3. **The shaker's K(s)** (`_through_shaker`): the force per displacement of the driving point, K = P / X, is
   the attached shaker's -Z_sh(s) (armature, suspension, coil: m_a s^2 + c_s s + k_s + Bl Bl_e s / (L s + R)),
   a function of s alone, not of the amplitude. Along a decay s moves by about 1%, so K is fitted over the
   windows as K_0 + K_1 (s - mean s) (weighted by the force's noise; windows `OUTLIER` errors off left out:
   the first after the cut, where the force is not yet the shaker's reaction alone, and which then take their
   s from the response alone: the joint fit had read its zeta 3.6% high), and each window reads the fitted K
   at its s. The force's noise then averages over
   the decay, and the read goes as far down as the decay rate is known (on the virtual beam, with the
   response alone fitting s, 1.6-1.75 decades where each window's own K had stopped at 1.2-1.7).
   ``K_chi2`` is the fit's mean squared normalised residual: about 1 for a linear shaker (1.2 on the linear
   rig, 2.5 on the exact Iwan beam's, the first windows left out); a shaker whose suspension or coil is not
   linear over the stroke shows above it.
4. **The structure** (`structure_pole`) at each window's amplitude q_in = |X - R P|.

Checked against closed forms (tests/measure/test_forced_decay.py): the coupled rig's eigenvector gives the
structure's own wn and zeta to 1e-14 (its pole 2.3% below, zeta 1.43x); a linear 100 Hz mode on a linear
shaker (armature, suspension, coil; with and without a 230 Hz second mode), dwelt and cut, at 0.1% noise:
f within 0.016%, zeta within 1.7% over 1.79-1.81 decades (read as a free decay: the rig's pole, 2.3% low);
the exact Iwan beam on its shaker (rigs.py's top level): f within 0.017%, zeta within 1.3% (mean +0.6%: the
joint's share read at the rig's frequency, above) of the structure's first-harmonic balance over 1.71
decades, A = 1/m and R the second mode's there. In a virtual force campaign, A and R measured by its own
lowest-level sweep (`jointcal.measure.receptance`; A 0.29% low; tests/synth/test_forced_ringdown.py): 1.92
decades, f within 0.025%, zeta within 2.2%; over three seeds, tests/benchmarks/accept_testkinds.py.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import signal
from scipy.optimize import least_squares

from ..units import G
from ._decay_window import fit_window
from .ringdown import (BAND, EXTEND, MISFIT_MAX, MIN_CYCLES, TAIL, ZETA_SE_MAX, decay_start,
                       slide_windows)

__all__ = ["structure_pole", "forced_decay_backbone", "COLUMNS", "SETTLE_LIVE", "ZETA_SE_LIVE", "OUTLIER"]

ZETA_SE_LIVE = (3 * ZETA_SE_MAX - 0.006) / 3  # zeta's standard error within this share of it: the ring-down's
# three standard errors within 3%, less the +0.6% bias of a joint's share read at the rig's frequency (0.8%)
OUTLIER = 4.0  # a window's K this many standard errors off the fit over the decay is left out of it
SETTLE_LIVE = 3.0  # periods after the decay's start left out: the start found from the response's plateau lies
# up to half a period before the cut (4.4 ms at 97 Hz on the virtual beam), and the force is not the shaker's
# reaction alone for a period or two after it (at 2 periods the first window's zeta read up to 4% off)

COLUMNS = ["t_s", "window_s", "q_in", "f_hz", "zeta", "zeta_se", "f_se_hz", "f_rig_hz", "zeta_rig", "force_share",
           "K_chi2", "misfit", "flags"]


def structure_pole(s: ArrayLike, K: ArrayLike, modal_constant: complex,
                   residual: complex = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The structure's own natural frequency and damping from the force per displacement at a decay's frequency.

    Parameters
    ----------
    s : array_like of complex, shape (k,)
        The decay's complex frequency -sigma + i w per window, 1/s (w > 0).
    K : array_like of complex, shape (k,)
        The measured force over displacement at s, P / X (lbf/in): the inverse of the receptance H = X / P;
        0 for a free decay.
    modal_constant : complex
        A, (in/s^2) per lbf: 1/m for a force at the driving point.
    residual : complex
        The other modes' receptance at the driving point near this one, R (in/lbf; 0: none).

    Returns
    -------
    wn : ndarray, shape (k,)
        Natural frequency, rad/s: wn^2 = Re(Y) + c' sigma with Y = A / (H - R) - s^2 = A K / (1 - R K) - s^2
        and c' = Im(Y) / w; NaN where wn^2 <= 0.
    zeta : ndarray, shape (k,)
        Damping ratio c' / (2 wn) (viscous at w; see the module docstring for a joint's share).
    """
    s = np.atleast_1d(np.asarray(s, complex))
    K = np.atleast_1d(np.asarray(K, complex))
    if not np.all(s.imag > 0):
        raise ValueError(f"the decay's complex frequency must have a positive imaginary part (w > 0), got {s!r}.")
    Y = complex(modal_constant) * K / (1.0 - complex(residual) * K) - s**2
    c = Y.imag / s.imag
    wn2 = Y.real - c * s.real
    wn = np.sqrt(np.where(wn2 > 0, wn2, np.nan))
    return wn, c / (2 * wn)


def _basis(p: NDArray, t: NDArray) -> NDArray:
    w, sig, r, sd = p
    env = np.exp(-sig * t - 0.5 * sd * t * t)
    ph = w * t + 0.5 * r * t * t
    return np.column_stack([env * np.cos(ph), env * np.sin(ph)])


def _pair_window(t: NDArray, x: NDArray, F: NDArray, w0: float, sig0: float,
                 ratio: float) -> tuple[complex, complex, complex, float, tuple[float, float], float, complex]:
    """One window of both channels as one decaying oscillation: a damped sinusoid, its frequency and decay rate
    drifting linearly over the window, with each channel's own amplitude and phase.

    The nonlinear parameters (w, sigma and their drifts) are fitted to both channels at once, the force's
    residual weighted by `ratio` (the response's noise over the force's: both in units of the response's noise),
    the amplitudes by variable projection; started from the response's own fit (`fit_window`). Returns
    s = -sigma + i w at the window's centre (1/s), the phasors of x and F there (their units; the signal is
    Re(phasor e^{i w t}) near t = 0), the response's relative rms misfit, and per unit rms of the response's
    white noise the standard errors of w and sigma (rad/s, 1/s), and per unit of the force's that of the force's phasor
    (sqrt of the trace of (B^T B)^-1); last, s from the response alone (`fit_window`).
    """
    w, sig, *_ = fit_window(t, x, w0, sig0)
    span = max(float(np.ptp(t)), 1.0 / w)
    scale = np.array([1.0 / span, 1.0 / span, 1.0 / span**2, 1.0 / span**2])  # a unit step moves the phase ~1 rad
    both = np.column_stack([x, F])

    def misfit(u):
        B = _basis(u * scale, t)
        r = both - B @ np.linalg.lstsq(B, both, rcond=None)[0]
        return np.concatenate([r[:, 0], ratio * r[:, 1]])

    sol = least_squares(misfit, np.array([w, sig, 0.0, 0.0]) / scale, method="lm")
    p = sol.x * scale
    B = _basis(p, t)
    (ax, bx), (aF, bF) = np.linalg.lstsq(B, both, rcond=None)[0].T
    res = float(np.sqrt(np.mean(misfit(sol.x)[:t.size] ** 2)) / max(np.hypot(ax, bx) / np.sqrt(2), 1e-300))
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac)
        se_w, se_sig = float(np.sqrt(cov[0, 0]) * scale[0]), float(np.sqrt(cov[1, 1]) * scale[1])
        se = float(np.sqrt(np.trace(np.linalg.inv(B.T @ B))))
    except np.linalg.LinAlgError:
        se_w = se_sig = se = np.inf
    return complex(-p[1], p[0]), complex(ax, -bx), complex(aF, -bF), res, (se_w, se_sig), se, complex(-sig, w)


def _apart(x: NDArray, F: NDArray, i0: int, n: int, fs: float, f_hz: float) -> tuple[NDArray, NDArray]:
    """Both channels band-passed, each decay from `i0` on apart from the forced part before it.

    As `jointcal.measure.ringdown` does for the response: the decay's first `n` samples are fitted by the
    response's damped sinusoid (the force on its basis), continued `EXTEND` periods backwards, and the
    continuation and the decay band-passed together (twice: raw, then band-passed), so that the filter sees no
    forced part and no edge at the cut. What the damped sinusoid leaves of those first samples (other modes
    ringing from the cut: the beam's 230 Hz mode; the joint's harmonics) is faded in by a raised cosine over
    the `SETTLE_LIVE` periods after the cut, which are not read: cut in abruptly at the junction its onset would ring
    through the band-pass.
    """
    sos = signal.butter(4, [f_hz * (1 - BAND), f_hz * (1 + BAND)], btype="bandpass", fs=fs, output="sos")
    x, F = x - np.median(x), F - np.median(F)
    y, g = signal.sosfiltfilt(sos, x), signal.sosfiltfilt(sos, F)
    if i0 + n > x.size:
        return y, g
    pad = int(round(EXTEND * fs / f_hz))
    tw = (np.arange(n) - (n - 1) / 2) / fs
    t_pad = (np.arange(-pad, 0) - (n - 1) / 2) / fs
    m = min(n, max(2, int(round(SETTLE_LIVE * fs / f_hz))))  # faded in over the periods left out after the cut
    fade = np.minimum(0.5 - 0.5 * np.cos(np.pi * np.arange(n) / m), 1.0) * (np.arange(n) < m) + (np.arange(n) >= m)
    sx, sF = x, F
    for _ in range(2):
        w, sig, *_ = fit_window(tw, sx[i0:i0 + n], 2 * np.pi * f_hz)
        B = _basis(np.array([w, sig, 0.0, 0.0]), tw)
        coef = np.linalg.lstsq(B, np.column_stack([sx[i0:i0 + n], sF[i0:i0 + n]]), rcond=None)[0]
        cont = _basis(np.array([w, sig, 0.0, 0.0]), t_pad) @ coef
        head = B @ coef
        out = []
        for j, (full, raw) in enumerate(((y, x), (g, F))):
            dec = raw[i0:].copy()
            dec[:n] = head[:, j] + fade * (dec[:n] - head[:, j])
            out.append(np.concatenate([full[:i0], signal.sosfiltfilt(sos, np.concatenate([cont[:, j], dec]))[pad:]]))
        sx, sF = out
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
        The mode's approximate frequency, Hz: the band-pass's centre (the decay's, the rig's, frequency).
    modal_constant : complex
        A, (in/s^2) per lbf (1/m), measured in the same campaign (a sweep's or the dwells' fit).
    residual : complex
        The other modes' receptance at the driving point near the mode, in/lbf.
    start : int, optional
        First sample of the decay; default `jointcal.measure.ringdown.decay_start` (with a force that stays
        live after the cut: where the response leaves its plateau). The `SETTLE_LIVE` periods after it are
        not read.
    min_cycles : float
        The shortest window, periods of the mode.

    Returns
    -------
    DataFrame
        One row per window, in time order: ``t_s`` (its centre, s from the record's start), ``window_s``
        (its length, s), ``q_in`` (the structure's displacement amplitude at the centre, in: |X - R P|),
        ``f_hz`` and ``zeta`` (the structure's own, `structure_pole`; Hz), ``zeta_se`` and ``f_se_hz`` (their
        standard errors from both channels' noise; Hz), ``f_rig_hz`` and ``zeta_rig`` (the decay's own pole |s| / 2 pi and
        sigma / |s|: the coupled rig's, what `ringdown_backbone` reads), ``force_share`` (|A P / X| / |s|^2:
        how much of the decay the force carries; 0 for a free decay), ``misfit`` (the response's relative
        rms residual) and ``flags`` (``noise_floor`` on the last row read, ``misfit``).
    """
    x = np.nan_to_num(np.asarray(response_g, float))
    F = np.nan_to_num(np.asarray(force_lbf, float))
    if x.shape != F.shape:
        raise ValueError(f"the response ({x.size} samples) and the force ({F.size}) must be one record's channels.")
    A = complex(modal_constant)
    if not (np.isfinite(A) and A != 0):
        raise ValueError(f"the modal constant must be a finite, nonzero number ((in/s^2) per lbf), "
                         f"got {modal_constant!r}.")
    if not (np.isfinite(f_hz) and 0 < f_hz * (1 + BAND) < fs / 2):
        raise ValueError(f"the mode's frequency {f_hz!r} Hz must lie below the record's Nyquist frequency "
                         f"{fs / 2:g} Hz.")
    if start is None:
        sos = signal.butter(4, [f_hz * (1 - BAND), f_hz * (1 + BAND)], btype="bandpass", fs=fs, output="sos")
        start = decay_start(fs, signal.sosfiltfilt(sos, x - np.median(x)), F - np.median(F))
    n = max(16, int(round(min_cycles * fs / f_hz)))
    y, g = _apart(x, F, int(start), n, fs, f_hz)
    lo = int(start) + int(round(SETTLE_LIVE * fs / f_hz))  # the ring at the cut and the fade left out
    tail = max(n, int(TAIL * y.size))  # the band-passed records' rms where the decay has died out: the noise
    noise_x, noise_F = (float(np.sqrt(np.mean(v[-tail:] ** 2))) for v in (y, g))
    per_sample = np.sqrt(fs / (4 * BAND * f_hz))  # one independent noise sample in fs / 2B (as ringdown's)

    def read(lo, n, w0, sig0):
        row, s = _read(y, g, lo, n, fs, w0, sig0, A, complex(residual), noise_x * per_sample, noise_F * per_sample)
        ok = bool(np.isfinite(row["zeta"]) and row["zeta"] > 0)
        return row, s.imag, -s.real, row["zeta_se"] / row["zeta"] if ok else np.inf, ok

    rows = slide_windows(read, y.size, lo, n, 2 * np.pi * f_hz, fs, ZETA_SE_LIVE)
    return _through_shaker(pd.DataFrame(rows), A, complex(residual))


def _through_shaker(t: pd.DataFrame, A: complex, R: complex) -> pd.DataFrame:
    """Each window's structure read with the attached shaker's K(s) fitted over the decay (step 3 above)."""
    if t.empty:
        return pd.DataFrame(columns=COLUMNS)
    s, K, se_K = t["s"].to_numpy(complex), t["K"].to_numpy(complex), t["K_se"].to_numpy(float)
    s0 = s.mean()
    ds = (s - s0) / abs(s0)
    B = np.column_stack([np.ones_like(ds), ds])[:, :1 if s.size < 3 else 2]
    wt = 1.0 / np.maximum(se_K, 1e-300 + 1e-12 * np.abs(K))
    coef, *_ = np.linalg.lstsq(B * wt[:, None], K * wt, rcond=None)
    far = np.abs((K - B @ coef) * wt) > OUTLIER
    if 0 < far.sum() <= s.size - 3:  # windows off the shaker's K by more than OUTLIER errors: out of its fit
        wt = np.where(far, 0.0, wt)
        coef, *_ = np.linalg.lstsq(B * wt[:, None], K * wt, rcond=None)
    if far.any():  # there the force is not yet the shaker's reaction alone: the decay's s from the response
        s = np.where(far, t["s_resp"].to_numpy(complex), s)
        B = np.column_stack([np.ones_like(ds), (s - s0) / abs(s0)])[:, :B.shape[1]]
    fit = B @ coef
    se_fit = np.sqrt(np.einsum("ij,jk,ik->i", B, np.linalg.pinv((B * wt[:, None]).conj().T @ (B * wt[:, None])),
                               B.conj()).real)  # the fitted K's standard error at each window
    wn, z = structure_pole(s, fit, A, R)
    dz = np.abs(A) * se_fit / (2 * s.imag * wn)  # through Im(A K) / w
    df = np.abs(A) * se_fit / (2 * wn) / (2 * np.pi)  # through Re(A K) in wn^2, Hz
    return t.assign(f_hz=wn / (2 * np.pi), zeta=z, zeta_se=np.hypot(t["zeta_se_rate"], dz),
                    f_se_hz=np.hypot(t["f_se_hz"], df),
                    f_rig_hz=np.abs(s) / (2 * np.pi), zeta_rig=-s.real / np.abs(s),
                    K_chi2=float(np.sum(np.abs((K - fit) * wt) ** 2) / max(np.count_nonzero(wt), 1)))[COLUMNS]


def _read(y: NDArray, g: NDArray, lo: int, n: int, fs: float, w0: float, sig0: float, A: complex, R: complex,
          noise_x: float, noise_F: float) -> tuple[dict, complex]:
    """One window y[lo:lo + n], g[lo:lo + n] read with its own K = P / X: its row and its s (1/s).

    noise_x, noise_F: the channels' noise per independent sample (g, lbf). The row's ``zeta_se`` is the decay
    rate's share alone (the stop rule's: K is then fitted over the decay, `_through_shaker`); ``K_se`` is K's
    standard error from the force's noise."""
    t = (np.arange(n) - (n - 1) / 2) / fs
    s, px, pF, res, (se_w, se_sig), se_p, s_resp = _pair_window(t, y[lo:lo + n], g[lo:lo + n], w0, sig0,
                                                noise_x / noise_F if noise_F > 0 else 0.0)
    X = px * G / s**2  # displacement, in
    wn, z = (float(v[0]) for v in structure_pole(s, pF / X, A, R))
    share = abs(A * pF / X) / abs(s) ** 2
    se_rate = se_sig * noise_x / wn  # zeta's standard error from the decay rate's (c' holds 2 sigma)
    row = dict(t_s=(lo + (n - 1) / 2) / fs, window_s=n / fs, q_in=abs(X - R * pF), f_hz=wn / (2 * np.pi), zeta=z,
               zeta_se=se_rate, zeta_se_rate=se_rate, f_se_hz=se_w * noise_x / (2 * np.pi),
               f_rig_hz=abs(s) / (2 * np.pi), zeta_rig=-s.real / abs(s),
               force_share=share, misfit=res, flags="misfit" if res > MISFIT_MAX else "", s=s, K=pF / X,
               K_se=abs(pF / X) * se_p * noise_F / max(abs(pF), 1e-300), s_resp=s_resp)
    return row, s
