"""The truth of a shaker-rig run (`jointcal.synth.shaker`): what its FRFs show at a drive level.

Truth at a drive level V0 (`rig_truth`), from the equivalent-linear (first-harmonic)
coupled FRF: the structure's own natural frequency and damping (what H1 of response /
force shows) at the steady-state amplitude at its own phase resonance, and the rig's
pole (what H1 of response / voltage shows) at the steady-state amplitude at the rig's
resonance. For a nonlinear joint the two amplitudes differ: the rig's resonance lies
below the structure's (armature mass), and at the structure's the force drops out.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..models import MinistackModel, harmonic_balance
from ..models.iwan import derived
from .non_masing import equivalent, share_of
from .shaker import BL_E_PER_BL, Shaker, StructureMode, _structure

__all__ = ["peak_amplitude", "structure_equivalent", "rig_pole", "steady_amplitude", "structure_resonance_amplitude",
           "rig_truth"]


def structure_equivalent(model: MinistackModel, q: float) -> tuple[float, float]:
    """The structure's equivalent-linear natural frequency (Hz) and damping at amplitude q (in).

    First-harmonic balance of the joint (`jointcal.models.harmonic_balance`, dashpot
    viscous term; with a backbone share, `jointcal.synth.non_masing.equivalent`); a linear
    structure (no joint) gives sqrt(k/m) and zeta_v.
    """
    if model.iwan is None:
        return float(np.sqrt(model.k / model.m) / (2 * np.pi)), float(model.zeta_v)
    if share_of(model) > 0:  # a non-Masing joint: its cycle integrated (jointcal.synth.non_masing)
        return equivalent(model, q)
    p = model.iwan
    f, z = harmonic_balance(q, p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    return float(f), float(z)


def _structure_terms(model: MinistackModel, q: float) -> tuple[float, float, float]:
    """The structure's first-harmonic dynamic stiffness at amplitude q (in).

    Returns k_df (in-phase stiffness, lbf/in), c (the dashpot, lbf s/in) and h (the
    joint's hysteretic loss stiffness D(q) / (pi q^2), lbf/in: its energy per cycle does
    not depend on frequency), so S(w) = k_df - m w^2 + i (w c + h).
    """
    ks, c, m = _structure(model)
    f, z = structure_equivalent(model, q)
    w = 2 * np.pi * f
    k_df = m * w**2
    w0 = np.sqrt(ks / m)
    h = 0.0 if model.iwan is None else 2.0 * k_df * (z - model.zeta_v * w0 / w)  # HB zeta less the dashpot's
    return k_df, c, h


def _electrical(shaker: Shaker):
    return (shaker.bl_lbf_per_A, shaker.bl_lbf_per_A * BL_E_PER_BL, shaker.coil_mH * 1e-3, shaker.coil_ohm)


def _x_over_v(model: MinistackModel, shaker: Shaker, q: float, w: NDArray,
              second: StructureMode | None = None) -> NDArray:
    """The equivalent-linear rig's FRF x / V (in/V) at amplitude q and frequencies w (rad/s).

    With S_1 = k_df - m w^2 + i (w c + h) the jointed mode, S_2 the second mode's dynamic
    stiffness, S_a the armature's on its suspension and u = x (1 + S_1 / S_2):
    x [(R + i w L)(S_a (1 + S_1 / S_2) + S_1) / Bl + i w Bl_e (1 + S_1 / S_2)] = V.
    """
    k_df, c, h = _structure_terms(model, q)
    Bl, Ble, L, R = _electrical(shaker)
    s1 = k_df - model.m * w**2 + 1j * (w * c + h)
    sa = shaker.k_s - shaker.m_a * w**2 + 1j * w * shaker.c_s
    ratio = 1.0 if second is None else 1.0 + s1 / (second.k - second.m * w**2 + 1j * w * second.c)
    return 1.0 / ((R + 1j * w * L) * (sa * ratio + s1) / Bl + 1j * w * Ble * ratio)


def _rig_poly(model: MinistackModel, shaker: Shaker, q: float, w_eval: float | None = None,
              second: StructureMode | None = None):
    """Characteristic polynomial (in s) of the equivalent-linear rig at amplitude q, and Bl.

    (R + L s)(S_a (S_2 + S_1) + S_1 S_2) + Bl Bl_e s (S_2 + S_1) (S_2 = 1 without a second
    mode: (R + L s)(S_a + S_1) + Bl Bl_e s), S_j = m_j s^2 + c_j s + k_j. The joint's
    hysteretic loss h enters as the viscous h / w_eval (exact at w_eval, default the
    structure's own frequency; `rig_pole` iterates it to the pole's).
    """
    k_df, c, h = _structure_terms(model, q)
    w_eval = np.sqrt(k_df / model.m) if w_eval is None else w_eval
    Bl, Ble, L, R = _electrical(shaker)
    s1 = np.array([model.m, c + h / w_eval, k_df])
    sa = np.array([shaker.m_a, shaker.c_s, shaker.k_s])
    if second is None:
        mech, emf = np.polyadd(sa, s1), np.array([Bl * Ble, 0.0])
    else:
        s2 = np.array([second.m, second.c, second.k])
        both = np.polyadd(s2, s1)
        mech = np.polyadd(np.polymul(sa, both), np.polymul(s1, s2))
        emf = np.polymul([Bl * Ble, 0.0], both)
    return np.polyadd(np.polymul([L, R], mech), emf), Bl


def rig_pole(model: MinistackModel, shaker: Shaker, q: float,
             second: StructureMode | None = None) -> tuple[float, float]:
    """The rig's structural pole at amplitude q: |lambda| / 2 pi (Hz) and -Re(lambda) / |lambda|.

    The joint's hysteretic loss is taken as the equivalent viscous damping at the
    pole's own frequency (a fixed point, three iterations: converged to < 1e-9); with a
    second mode, the pole of the jointed mode (the one nearest its own frequency).
    """
    w = 2 * np.pi * structure_equivalent(model, q)[0]
    for _ in range(4):
        r = np.roots(_rig_poly(model, shaker, q, w, second)[0])
        r = r[np.imag(r) > 0]
        lam = r[np.argmin(np.abs(np.abs(r) - w))]
        w = abs(lam)
    return float(abs(lam) / (2 * np.pi)), float(-lam.real / abs(lam))


def _self_consistent(model: MinistackModel, amp, iterations: int = 60) -> float:
    """The amplitude q (in) with amp(q) = q, by bisection in log q (a single root for a softening joint)."""
    if model.iwan is None:
        return float(amp(1.0))
    phimax = float(derived(model.iwan.Fs, model.iwan.KT, model.iwan.chi, model.iwan.beta)[0])
    lo, hi = np.log(1e-9 * phimax), np.log(1e3 * phimax)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if amp(np.exp(mid)) > np.exp(mid) else (lo, mid)
    return float(np.exp(0.5 * (lo + hi)))


def steady_amplitude(model: MinistackModel, shaker: Shaker, volts: float,
                     second: StructureMode | None = None) -> float:
    """Steady-state displacement amplitude (in) at the rig's resonance under a voltage amplitude (V).

    Solves q = V max_w |x/V(w; q)|, with the joint's first-harmonic stiffness and
    hysteretic loss at q.
    """
    def peak(q):
        w = 2 * np.pi * structure_equivalent(model, q)[0] * np.linspace(0.7, 1.3, 4001)
        return volts * np.max(np.abs(_x_over_v(model, shaker, q, w, second)))

    return _self_consistent(model, peak)


def structure_resonance_amplitude(model: MinistackModel, shaker: Shaker, volts: float,
                                  second: StructureMode | None = None) -> float:
    """Steady-state amplitude (in) at the STRUCTURE's phase resonance under a voltage amplitude (V).

    Where x / F is in quadrature the structure's equivalent-linear stiffness balances
    its inertia, w = w_hb(q); there the rig is off its own (mass-loaded) resonance and
    the force drops out, so the amplitude is smaller than `steady_amplitude`. Solves
    q = V |x/V(w_hb(q); q)|.
    """
    def amp(q):
        w = np.array([2 * np.pi * structure_equivalent(model, q)[0]])
        return volts * float(np.abs(_x_over_v(model, shaker, q, w, second))[0])

    return _self_consistent(model, amp)


def _reached(t: NDArray, f_inst: NDArray, x: NDArray, f: float, zeta: float) -> float:
    """Largest |x| (in) while the drive is within +-zeta f / 2 of f (Hz), allowing the response's lag.

    The response lags the drive by about 1/(zeta w): the window looks that far past the crossing.
    """
    ahead = np.interp(t - 1.0 / (2 * np.pi * f * zeta), t, f_inst)
    near = np.abs(ahead - f) <= 0.5 * zeta * f
    return float(np.max(np.abs(x[near]))) if near.any() else float("nan")


def peak_amplitude(x: NDArray, fs: float, f_hz: float, cutoff: float = 0.45) -> float:
    """The largest amplitude (in) of the displacement x near f_hz: its envelope demodulated at f_hz
    and low-passed at cutoff f_hz (the mode's passage and ring-down; not the drive far from it, other
    modes or harmonics), the same band as the measured check `jointcal.measure.modal.band_envelope_peak`."""
    from ..measure.sweepfit import baseband
    return float(np.abs(baseband(np.asarray(x, float), fs, 2 * np.pi * f_hz, cutoff * f_hz)).max())


def _shape_at_driving_point(model: MinistackModel, shaker: Shaker, q: float,
                            second: StructureMode | None) -> float:
    """|u / x| of the rig's mode at amplitude q: 1 + S_1 / S_2 at its pole (1 without a second mode)."""
    if second is None:
        return 1.0
    fr, zr = rig_pole(model, shaker, q, second)
    w = 2 * np.pi * fr
    k_df, c, h = _structure_terms(model, q)
    s1 = k_df - model.m * w**2 + 1j * (w * c + h)
    return float(abs(1.0 + s1 / (second.k - second.m * w**2 + 1j * w * second.c)))


def rig_truth(model: MinistackModel, shaker: Shaker, volts: float, t: NDArray | None = None,
              f_inst: NDArray | None = None, x: NDArray | None = None, *,
              second: StructureMode | None = None) -> dict:
    """Truth of one rig run at drive amplitude `volts` (V).

    Parameters
    ----------
    model, shaker, volts : the rig and the amplifier's voltage amplitude (V).
    t, f_inst, x : ndarray, optional
        The simulated sweep: time (s), drive frequency (Hz) and the jointed mode's
        displacement (in), to read the amplitude the sweep actually reached near each resonance.
    second : StructureMode, optional
        A second, linear mode at the driving point.

    Returns
    -------
    dict
        q_ss_in, f_hb_hz, zeta_hb: the structure alone (what H1 of response / force
        shows) at the steady-state amplitude at its own phase resonance;
        q_rig_ss_in, f_rig_hz, zeta_rig: the rig's pole (what H1 of response /
        voltage shows) at the steady-state amplitude at the rig's resonance; with the
        sweep, the same at the largest amplitude reached while the drive was within
        +-zeta f / 2 of that resonance (q_reached_in, f_hb_hz_reached, ... a fast chirp
        never builds the steady state), suffixed _reached; and q_peak_in, the largest
        amplitude the jointed mode reached over the whole record (its band-limited
        envelope's peak: the passage and the ring-down; the amplitude a force-driven
        read-out's q_in must equal: the second mode's share is a residual of the force),
        and q_rig_peak_in, the rig's mode as the sensor at the driving point sees it (the
        jointed mode's peak times |u / x| of the rig's mode, 1 + S_1/S_2 at its pole: the
        second mode's share in that mode; a voltage-driven read-out's q_in).
    """
    q_s, q_r = (structure_resonance_amplitude(model, shaker, volts, second),
                steady_amplitude(model, shaker, volts, second))
    f, z = structure_equivalent(model, q_s)
    fr, zr = rig_pole(model, shaker, q_r, second)
    out = dict(q_ss_in=q_s, f_hb_hz=f, zeta_hb=z, q_rig_ss_in=q_r, f_rig_hz=fr, zeta_rig=zr)
    if x is not None:
        qs, qr = _reached(t, f_inst, x, f, z), _reached(t, f_inst, x, fr, zr)
        none = (float("nan"), float("nan"))  # an amplitude not reached (a dwell off the resonance's band)
        f2, z2 = structure_equivalent(model, qs) if np.isfinite(qs) else none
        fr2, zr2 = rig_pole(model, shaker, qr, second) if np.isfinite(qr) else none
        fs = 1.0 / float(t[1] - t[0])
        out.update(q_reached_in=qs, f_hb_hz_reached=f2, zeta_hb_reached=z2, q_rig_reached_in=qr,
                   f_rig_hz_reached=fr2, zeta_rig_reached=zr2, q_peak_in=peak_amplitude(x, fs, f))
        qx = peak_amplitude(x, fs, fr)
        out["q_rig_peak_in"] = qx * _shape_at_driving_point(model, shaker, qx, second)
    return out
