"""Resonance and damping of a swept run from its whole transient, at the amplitude it reached.

A lab's FRF (`jointcal.frf`) assumes each line is a steady state. A chirp faster than a
lightly damped nonlinear mode can follow breaks that: the amplitude never builds, the
response rings on after the drive has moved away, and a softening joint's peak is read
at amplitudes it never had. Here the run is instead fitted, sample by sample, with one
mode whose natural frequency and damping depend on its amplitude, driven by the
measured reference:

    x_a'' + (1 - phi) D(q) x_a' + (Omega(q)^2 + i phi D(q) Omega(q)) x_a = A r_a(t),    q = |x_a|,

with x_a, r_a the analytic (Hilbert) signals of the displacement and the reference,
D = 2 zeta Omega shared between a viscous part and a hysteretic part phi (a joint's
friction: its loss per cycle does not grow with frequency; phi matters where the data lie
off Omega, e.g. a force-driven rig's response peaks at the shaker-loaded resonance), and
A a complex modal constant, linear in the drive frequency, A = A_0 + A_1 (w / Omega_0 - 1) (a force's is 1/m; an amplifier voltage's carries the shaker's
electrical phase). In a frame rotating with the drive, x_a = Z e^{i theta}, w = theta',
this is exactly

    Z'' + (2 i w + c) Z' + (Omega^2 - w^2 + i (c w + phi D Omega + w')) Z = A R,   c = (1 - phi) D,

with R = r_a e^{-i theta} and Z slowly varying: integrated by RK4 at a few steps per
cycle (the negative-frequency root -(Omega + w) bounds the step), its acceleration
Z'' + 2 i w Z' + (i w' - w^2) Z is compared with the measured one. For a linear mode this
is the exact response at any sweep rate; for an amplitude-dependent one it is the
first-harmonic (averaged) response, the same approximation as the harmonic-balance
truth. Omega^2(q) and D(q) are quadratics in s = q / q_ref - 1 around the largest
amplitude the run reached, q_ref; the fit (`scipy.optimize.least_squares`, the modal
constant, the six shape coefficients and phi in [0, 1]) returns Omega and
zeta = D / (2 Omega) at the amplitude the
fitted response reached: the equivalent-linear resonance and damping at the run's level.
Measured on synthetic force- and voltage-driven rigs (tests/benchmarks/accept_rigs.py):
within 0.1% and 5% of the truth at that amplitude for eta 0.1-20, the Table 3.2 joint
included, where the FRF read-outs of the same runs miss by up to 7%.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray
from scipy import signal
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import least_squares

from .models import G

__all__ = ["SweepFit", "rotating_frame", "fit_swept_mode"]


@dataclass(frozen=True)
class SweepFit:
    """A swept run's amplitude-dependent single-mode fit.

    f_hz, zeta : natural frequency Omega / 2 pi (Hz) and damping ratio at q_in.
    q_in : the largest displacement amplitude the fitted response reached (in): the
        amplitude f_hz and zeta belong to.
    q_low_in : the smallest amplitude the fitted window holds (in); the backbone
        (`backbone`) is fitted over [q_low_in, q_in].
    residual : relative RMS misfit of the response's acceleration envelope over the window.
    coef : (Omega_ref^2 (rad^2/s^2), D_ref (1/s), a1, a2, b1, b2, phi, q_ref (in)):
        Omega^2 = Omega_ref^2 (1 + a1 s + a2 s^2), D = 2 zeta Omega = D_ref (1 + b1 s + b2 s^2),
        s = q / q_ref - 1; phi the hysteretic share of D (0 viscous, 1 hysteretic).
    """

    f_hz: float
    zeta: float
    q_in: float
    q_low_in: float
    residual: float
    coef: tuple

    def backbone(self, q: NDArray) -> tuple[NDArray, NDArray]:
        """Natural frequency (Hz) and damping ratio at amplitudes q (in) (fitted over [q_low_in, q_in])."""
        w2r, dr, a1, a2, b1, b2, _, qr = self.coef
        s = np.asarray(q, float) / qr - 1.0
        om = np.sqrt(w2r * (1 + a1 * s + a2 * s**2))
        return om / (2 * np.pi), dr * (1 + b1 * s + b2 * s**2) / (2 * om)  # at w = Omega


@numba.njit(cache=True)
def _rhs(z, y, r, w, dw, p, q_ref):
    s = abs(z) / q_ref - 1.0
    w2 = p[0] * (1.0 + p[2] * s + p[3] * s * s)
    d = p[1] * (1.0 + p[4] * s + p[5] * s * s)  # 2 zeta Omega at q
    c = (1.0 - p[8]) * d  # the viscous share; the hysteretic share p[8] d Omega does not scale with w
    a = (p[6] + 1j * p[7]) + (p[9] + 1j * p[10]) * (w / p[11] - 1.0)  # the modal constant, sloped in w
    return a * r - (2j * w + c) * y - (w2 - w * w + 1j * (c * w + p[8] * d * np.sqrt(w2) + dw)) * z


@numba.njit(cache=True)
def _rotating_mode(r, w, dw, h, p, q_ref, z0):
    """RK4 of the rotating-frame mode from Z = z0, Z' = 0; returns Z (in) and its acceleration envelope (in/s^2)."""
    n = r.size
    Z = np.empty(n, np.complex128)
    acc = np.empty(n, np.complex128)
    z, y = z0 + 0j, 0j
    for k in range(n):
        a1 = _rhs(z, y, r[k], w[k], dw[k], p, q_ref)
        Z[k] = z
        acc[k] = a1 + 2j * w[k] * y + (1j * dw[k] - w[k] * w[k]) * z
        if k == n - 1:
            break
        rm, wm, dm = 0.5 * (r[k] + r[k + 1]), 0.5 * (w[k] + w[k + 1]), 0.5 * (dw[k] + dw[k + 1])
        a2 = _rhs(z + 0.5 * h * y, y + 0.5 * h * a1, rm, wm, dm, p, q_ref)
        a3 = _rhs(z + 0.5 * h * (y + 0.5 * h * a1), y + 0.5 * h * a2, rm, wm, dm, p, q_ref)
        a4 = _rhs(z + h * (y + 0.5 * h * a2), y + h * a3, r[k + 1], w[k + 1], dw[k + 1], p, q_ref)
        z = z + h * y + h * h / 6.0 * (a1 + a2 + a3)
        y = y + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return Z, acc


def rotating_frame(ref: NDArray, fs: float, f_hint: float, *, cycles: float = 4.0):
    """A frame rotating with the drive: its phase theta (rad) and frequency w = theta' (rad/s).

    The reference's instantaneous frequency (Hilbert phase), median- and mean-filtered over
    `cycles` periods at f_hint (a force gauge's signal drops out at resonance and carries the
    ring-down: the filter keeps the sweep), held at its end values where the drive is off
    (less than 10% of its peak), and integrated: any smooth frame is exact in the rotating
    equation as long as w = theta'.
    """
    ra = signal.hilbert(ref)
    n = max(3, int(cycles * fs / f_hint) | 1)
    env = np.convolve(np.abs(ra), np.ones(n) / n, mode="same")
    on = np.flatnonzero(env > 0.1 * env.max())
    i0, i1 = min(on[0] + n, ref.size - 2), max(on[-1] - n, on[0] + 1)
    w = np.gradient(np.unwrap(np.angle(ra))) * fs
    w = np.convolve(signal.medfilt(w, n), np.ones(n) / n, mode="same")
    w[:i0], w[i1:] = w[i0], w[i1 - 1]
    return cumulative_trapezoid(w, dx=1.0 / fs, initial=0.0), w


def _lowpass(x: NDArray, fs: float, fc: float) -> NDArray:
    sos = signal.butter(4, min(fc, 0.4 * fs), fs=fs, output="sos")
    return signal.sosfiltfilt(sos, x.real) + 1j * signal.sosfiltfilt(sos, x.imag)


def fit_swept_mode(ref: NDArray, resp_g: NDArray, fs: float, f0: float, zeta0: float, *,
                   modal_phase: float | None = None, window: float = 0.15,
                   steps_per_cycle: float = 6.0) -> SweepFit:
    """Fit one amplitude-dependent mode to a swept run (see the module docstring).

    Parameters
    ----------
    ref : ndarray, shape (n,)
        Reference channel (force, lbf; amplifier voltage, V; any unit: A absorbs it).
    resp_g : ndarray, shape (n,)
        Response acceleration at the driving point (or any point of a single mode), g.
    fs : float
        Sample rate, Hz.
    f0, zeta0 : float
        Start values: the resonance (Hz) and damping ratio from the FRF read-out.
    modal_phase : float, optional
        The modal constant's phase where physics fixes it (rad): 0 for a force on the
        structure (A = 1/m, no frequency dependence). None (an amplifier voltage): A complex
        and sloped in w.
    window : float
        Samples whose response envelope exceeds this fraction of its peak are fitted
        (the passage through resonance and the ring-down).
    steps_per_cycle : float
        RK4 steps per period at f0, about (the rotating frame's fast root -(Omega + w)
        bounds it: 6 keeps |lambda| h near 2.1, under RK4's 2.8).

    Returns
    -------
    SweepFit

    Raises
    ------
    ValueError
        When the record holds no drive or the response no passage through f0.
    """
    r = np.nan_to_num(np.asarray(ref, float))
    a = np.nan_to_num(np.asarray(resp_g, float)) * G
    r, a = r - np.median(r), a - np.median(a)
    if not (np.ptp(r) > 0 and np.ptp(a) > 0 and f0 > 0 and zeta0 > 0):
        raise ValueError("the swept-mode fit needs a drive, a response and start values f0 > 0, zeta0 > 0.")
    theta, w = rotating_frame(r, fs, f0)
    rot = np.exp(-1j * theta)
    fc = 0.45 * f0  # the frame's envelopes: keeps |Omega - w| up to 0.45 f0, drops 2w and the harmonics
    R = _lowpass(signal.hilbert(r) * rot, fs, fc)
    Acc = _lowpass(signal.hilbert(a) * rot, fs, fc)
    step = max(1, int(round(fs / (steps_per_cycle * f0))))
    R, Acc, w = R[::step], Acc[::step], w[::step]
    h = step / fs
    sub = int(np.ceil(steps_per_cycle * f0 * h))  # a record sampled under 6 per cycle: finer steps on the
    if sub > 1:                                   # envelopes (smooth below 0.45 f0), interpolated
        t = np.arange(R.size) * h
        tt = np.arange((R.size - 1) * sub + 1) * (h / sub)
        R, Acc, w = (np.interp(tt, t, x.real) + 1j * np.interp(tt, t, x.imag) if np.iscomplexobj(x)
                     else np.interp(tt, t, x) for x in (R, Acc, w))
        h = h / sub
    dw = np.gradient(w, h)
    mag = np.abs(Acc)
    sel = np.flatnonzero(mag > window * mag.max())
    # integrate from where the response is under 5% of its peak before the fitted window (its measured
    # state there, a forced response: Z = -Acc / w^2, Z' = 0; the small start error decays) to its end
    quiet = np.flatnonzero(mag[:sel[0]] < 0.05 * mag.max())
    i0 = int(quiet[-1]) if quiet.size else 0
    R, Acc, w, dw, mag = (x[i0:sel[-1] + 1] for x in (R, Acc, w, dw, mag))
    sel = mag > window * mag.max()
    z_start = complex(-Acc[0] / w[0] ** 2) if i0 > 0 else 0j
    ip = int(np.argmax(mag))
    q_ref = float(mag[ip] / w[ip] ** 2)
    W0 = 2 * np.pi * f0
    scale = float(mag.max())
    a0 = 1j * 2 * zeta0 * W0**2 * (-Acc[ip] / w[ip] ** 2) / R[ip] if abs(R[ip]) > 0 else 1.0 + 0j
    a_abs = abs(a0)

    fixed = modal_phase is not None  # a force: A = |A| e^{i phase} (1/m, phase 0), no slope
    free = np.array([0, 1, 2, 3, 4, 5, 6, 8] if fixed else list(range(11)))

    def params(pf):
        p = np.zeros(11)
        p[free] = pf
        a = p[6] * np.exp(1j * modal_phase) if fixed else p[6] + 1j * p[7]
        return np.array([W0**2 * np.exp(2 * p[0]), 2 * zeta0 * W0 * np.exp(p[1]), p[2], p[3], p[4], p[5],
                         a.real * a_abs, a.imag * a_abs, p[8], p[9] * a_abs, p[10] * a_abs, W0])

    def misfit(p):
        with np.errstate(all="ignore"):  # a trial step may diverge: a large misfit, not a warning
            res = (_rotating_mode(R, w, dw, h, params(p), q_ref, z_start)[1] - Acc)[sel] / scale
        res = np.where(np.isfinite(res) & (np.abs(res) < 1e3), res, 1e3)
        return np.concatenate([res.real, res.imag])

    a_start = (a0 * np.exp(-1j * modal_phase)).real if fixed else a0.real
    scale_x = np.array([1e-3, 0.1, 0.05, 0.05, 0.2, 0.2, 0.1, 0.1, 0.2, 0.5, 0.5])[free]
    bounds = (np.array([-np.inf] * 8 + [0.0] + [-np.inf] * 2)[free], np.array([np.inf] * 8 + [1.0] + [np.inf] * 2)[free])
    norm = np.linalg.norm(Acc[sel] / scale)
    best, rel = None, np.inf
    for dz in (0.0, np.log(0.5), np.log(2.0)):  # damping starts: the FRF's zeta of a bent peak can be far off
        p0 = np.array([0.0, dz, 0.0, 0.0, 0.0, 0.0, a_start / a_abs, a0.imag / a_abs, 0.5, 0.0, 0.0])[free]
        sol = least_squares(misfit, p0, x_scale=scale_x, bounds=bounds, max_nfev=100)
        if best is None or sol.cost < best.cost:
            best, rel = sol, float(np.linalg.norm(sol.fun) / norm)  # relative RMS misfit: SweepFit.residual
        if rel < 0.02:  # a good fit from the FRF's start: no more starts
            break
    p = params(best.x)
    Z, _ = _rotating_mode(R, w, dw, h, p, q_ref, z_start)
    q_top = float(np.abs(Z[sel]).max())
    coef = (*(float(v) for v in p[:6]), float(p[8]), q_ref)
    fit = SweepFit(f_hz=np.nan, zeta=np.nan, q_in=q_top, q_low_in=float(np.abs(Z[sel]).min()), residual=rel,
                   coef=coef)
    f, z = fit.backbone(q_top)
    return SweepFit(**{**fit.__dict__, "f_hz": float(f), "zeta": float(z)})
