"""An electrodynamic shaker driven open-loop by an amplifier's voltage, coupled to the structure.

The structure (slug of mass m on the spring k in parallel with the joint, dashpot c,
on a rigid base) is driven at the slug through a stiff stinger and a force gauge by a
shaker: armature mass m_a on its suspension (k_s, c_s), coil of resistance R and
inductance L in a magnetic field (force constant Bl, lbf/A; back-EMF constant
Bl_e = Bl * 0.1129848 V/(in/s), the same constant in SI). With the stinger rigid the
armature moves with the slug, x:

    (m + m_a) x'' + (c + c_s) x' + (k + KT + k_s) x + r_nl = Bl i      (mechanics)
    L i' + R i + Bl_e x' = V                                          (coil)
    F = Bl i - m_a x'' - c_s x' - k_s x                               (force gauge)

so the force the gauge reads is m x'' + c x' + k x + F_joint(x): the structure's own
dynamic stiffness times x, which is smallest at the structure's resonance (the force
drops out there), and the ratio response / voltage is the rig's FRF, the shaker's
mass, suspension and electrical damping Bl Bl_e / R included. The joint's nonlinear
remainder r_nl = F_iwan - KT x (and the effects' k3, c2 terms) enters as in
`jointcal.models.simulate`, whose exact-Iwan kernel integrates this 3-state system.

Truth at a drive level V0 (`rig_truth`), from the equivalent-linear (first-harmonic)
coupled FRF: the structure's own natural frequency and damping (what H1 of response /
force shows) at the steady-state amplitude at its own phase resonance, and the rig's
pole (what H1 of response / voltage shows) at the steady-state amplitude at the rig's
resonance. For a nonlinear joint the two amplitudes differ: the rig's resonance lies
below the structure's (armature mass), and at the structure's the force drops out.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import NDArray

from ..models import G, MinistackModel, harmonic_balance
from ..models import _integrator
from ..models._masing import kernel_constants
from ..models.iwan import derived
from ..models.simulate import _substep_maps, band_limited, fractional_delay, hermite_propagator

__all__ = ["Shaker", "BL_E_PER_BL", "rig_matrices", "simulate_rig", "structure_equivalent", "rig_pole",
           "steady_amplitude", "structure_resonance_amplitude", "rig_truth"]

BL_E_PER_BL = 4.448222 * 0.0254  # V/(in/s) of back-EMF per lbf/A of force constant (= 1 in SI)


@dataclass(frozen=True)
class Shaker:
    """Electrodynamic shaker parameters (units lbf, in, s, A, V, ohm, H).

    armature_weight_lbf : moving weight on the shaker side of the force gauge, lbf.
    suspension_hz : the armature's own frequency on its flexures, Hz.
    suspension_zeta : their damping ratio.
    bl_lbf_per_A : force constant Bl, lbf/A.
    coil_ohm : coil resistance (plus the amplifier's output resistance), ohm.
    coil_mH : coil inductance, mH.
    """

    armature_weight_lbf: float = 0.25
    suspension_hz: float = 20.0
    suspension_zeta: float = 0.05
    bl_lbf_per_A: float = 2.0
    coil_ohm: float = 1.5
    coil_mH: float = 0.15

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"shaker.{f.name} must be a positive number, got {v!r}.")

    @property
    def m_a(self) -> float:
        """Armature mass, lbf s^2/in."""
        return self.armature_weight_lbf / G

    @property
    def k_s(self) -> float:
        """Suspension stiffness, lbf/in."""
        return self.m_a * (2 * np.pi * self.suspension_hz) ** 2

    @property
    def c_s(self) -> float:
        """Suspension damping, lbf s/in."""
        return 2 * self.suspension_zeta * np.sqrt(self.k_s * self.m_a)


def _structure(model: MinistackModel) -> tuple[float, float, float]:
    """Stuck-joint stiffness k + KT (lbf/in), dashpot c (lbf s/in) and mass (lbf s^2/in)."""
    if model.fixture is not None:
        raise ValueError("a shaker rig drives the slug on a rigid base: the fixture_flexibility effect does not apply; "
                         "use reference: base for it.")
    ks = model.k + model.KT
    return ks, 2.0 * model.zeta_v * np.sqrt(ks * model.m), model.m


def rig_matrices(model: MinistackModel, shaker: Shaker):
    """State space of the coupled rig, state [x (in), x' (in/s), i (A)], input V (volts).

    Returns
    -------
    A (3, 3), bu (3,), bf (3,) : x' = A x + bu V + bf r_nl
    out : dict of (c, du, df) per output, y = c.x + du V + df r_nl:
        'accel' (in/s^2) and 'force' (lbf, the gauge).
    """
    ks, c, m = _structure(model)
    M, K, C = m + shaker.m_a, ks + shaker.k_s, c + shaker.c_s
    Bl, Ble = shaker.bl_lbf_per_A, shaker.bl_lbf_per_A * BL_E_PER_BL
    L, R = shaker.coil_mH * 1e-3, shaker.coil_ohm
    A = np.array([[0.0, 1.0, 0.0], [-K / M, -C / M, Bl / M], [0.0, -Ble / L, -R / L]])
    bu = np.array([0.0, 0.0, 1.0 / L])
    bf = np.array([0.0, -1.0 / M, 0.0])
    acc = (A[1].copy(), 0.0, -1.0 / M)
    ma = shaker.m_a
    force = (np.array([-shaker.k_s, -shaker.c_s, Bl]) - ma * A[1], 0.0, ma / M)
    return A, bu, bf, {"accel": acc, "force": force}


def simulate_rig(model: MinistackModel, shaker: Shaker, volts: NDArray, fs: float, *, omega_h: float = 0.3):
    """Response acceleration (g), gauge force (lbf) and displacement (in) under a drive voltage.

    Parameters
    ----------
    model : MinistackModel
        The structure (joint, k, zeta_v, mass; effects k3, c2, sensor_gain,
        sensor_delay_s apply as in `jointcal.models.simulate`).
    shaker : Shaker
    volts : ndarray, shape (N,)
        Amplifier output voltage, V, sampled at fs; the rig starts at rest.
    fs : float
        Sample rate, Hz.
    omega_h : float
        Largest w_0 h of the integration substeps at the coupled stuck-joint frequency.

    Returns
    -------
    accel_g, force_lbf, x_in : ndarray, shape (N,)
    """
    u = np.ascontiguousarray(volts, dtype=float)
    n_out = u.size
    A, bu, bf, outs = rig_matrices(model, shaker)
    ks, _, m = _structure(model)
    w0 = np.sqrt((ks + shaker.k_s) / (m + shaker.m_a))
    u, U = band_limited(u, fs, w0 / (2 * np.pi))  # as `simulate` reads its input
    fs = fs * U
    n_sub = max(1, int(np.ceil(w0 / (omega_h * fs))))
    H = 1.0 / fs
    h = H / n_sub
    Phi, Gu = hermite_propagator(A, bu, h)
    _, Gf = hermite_propagator(A, bf, h)
    Gsub, Wub = _substep_maps(Gu, n_sub)
    lz, lv = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    az, bzu, bzf = lv @ A, float(lv @ bu), float(lv @ bf)
    if model.iwan is None:
        joint, KT, R, chi, phimax, Fs = 0, 0.0, 0.0, 0.5, 1.0, 0.0
    else:
        p = model.iwan
        phimax, R, _ = (float(a) for a in derived(p.Fs, p.KT, p.chi, p.beta))
        R, chi = kernel_constants(R, p.chi)
        joint, KT, Fs = 1, p.KT, p.Fs
    res = {}
    for name, (cy, dyu, dyf) in outs.items():  # the same trajectory twice, two outputs
        y, x = np.empty_like(u), np.empty_like(u)
        _integrator.run(u, _integrator.rate(u, fs), H, Gsub, Wub, np.ascontiguousarray(Phi),
                        np.ascontiguousarray(Gf), lz, lv, az, bzu, bzf, np.ascontiguousarray(cy), float(dyu),
                        float(dyf), joint, KT, R, chi, phimax, Fs, np.zeros(0), np.zeros(0), float(model.k3),
                        float(model.c2), float(model.contact_k), float(model.contact_gap_in), y, x)
        res[name] = y[::U][:n_out].copy()
    x = x[::U][:n_out].copy()
    fs = fs / U
    acc = res["accel"]
    if model.sensor_delay_s != 0.0:
        acc = fractional_delay(acc, model.sensor_delay_s, fs)
    return acc * model.sensor_gain / G, res["force"], x


def structure_equivalent(model: MinistackModel, q: float) -> tuple[float, float]:
    """The structure's equivalent-linear natural frequency (Hz) and damping at amplitude q (in).

    First-harmonic balance of the joint (`jointcal.models.harmonic_balance`, dashpot
    viscous term); a linear structure (no joint) gives sqrt(k/m) and zeta_v.
    """
    if model.iwan is None:
        return float(np.sqrt(model.k / model.m) / (2 * np.pi)), float(model.zeta_v)
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


def _x_over_v(model: MinistackModel, shaker: Shaker, q: float, w: NDArray) -> NDArray:
    """The equivalent-linear rig's FRF x / V (in/V) at amplitude q and frequencies w (rad/s)."""
    k_df, c, h = _structure_terms(model, q)
    Bl, Ble, L, R = _electrical(shaker)
    mech = k_df + shaker.k_s - (model.m + shaker.m_a) * w**2 + 1j * (w * (c + shaker.c_s) + h)
    return Bl / ((R + 1j * w * L) * mech + 1j * w * Bl * Ble)


def _rig_poly(model: MinistackModel, shaker: Shaker, q: float, w_eval: float | None = None):
    """Characteristic polynomial (in s) of the equivalent-linear rig at amplitude q.

    The joint's hysteretic loss h enters as the viscous h / w_eval (exact at w_eval,
    default the structure's own frequency; `rig_pole` iterates it to the pole's).
    """
    k_df, c, h = _structure_terms(model, q)
    w_eval = np.sqrt(k_df / model.m) if w_eval is None else w_eval
    M, K, C = model.m + shaker.m_a, k_df + shaker.k_s, c + h / w_eval + shaker.c_s
    Bl, Ble, L, R = _electrical(shaker)
    return np.polymul([L, R], [M, C, K]) + np.array([0.0, 0.0, Bl * Ble, 0.0]), Bl


def rig_pole(model: MinistackModel, shaker: Shaker, q: float) -> tuple[float, float]:
    """The rig's structural pole at amplitude q: |lambda| / 2 pi (Hz) and -Re(lambda) / |lambda|.

    The joint's hysteretic loss is taken as the equivalent viscous damping at the
    pole's own frequency (a fixed point, three iterations: converged to < 1e-9).
    """
    w = 2 * np.pi * structure_equivalent(model, q)[0]
    for _ in range(4):
        r = np.roots(_rig_poly(model, shaker, q, w)[0])
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


def steady_amplitude(model: MinistackModel, shaker: Shaker, volts: float) -> float:
    """Steady-state displacement amplitude (in) at the rig's resonance under a voltage amplitude (V).

    Solves q = V max_w |x/V(w; q)|, with the joint's first-harmonic stiffness and
    hysteretic loss at q.
    """
    def peak(q):
        w = 2 * np.pi * structure_equivalent(model, q)[0] * np.linspace(0.7, 1.3, 4001)
        return volts * np.max(np.abs(_x_over_v(model, shaker, q, w)))

    return _self_consistent(model, peak)


def structure_resonance_amplitude(model: MinistackModel, shaker: Shaker, volts: float) -> float:
    """Steady-state amplitude (in) at the STRUCTURE's phase resonance under a voltage amplitude (V).

    Where x / F is in quadrature the structure's equivalent-linear stiffness balances
    its inertia, w = w_hb(q); there the rig is off its own (mass-loaded) resonance and
    the force drops out, so the amplitude is smaller than `steady_amplitude`. Solves
    q = V |x/V(w_hb(q); q)|.
    """
    def amp(q):
        w = np.array([2 * np.pi * structure_equivalent(model, q)[0]])
        return volts * float(np.abs(_x_over_v(model, shaker, q, w))[0])

    return _self_consistent(model, amp)


def _reached(t: NDArray, f_inst: NDArray, x: NDArray, f: float, zeta: float) -> float:
    """Largest |x| (in) while the drive is within +-zeta f / 2 of f (Hz), allowing the response's lag.

    The response lags the drive by about 1/(zeta w): the window looks that far past the crossing.
    """
    ahead = np.interp(t - 1.0 / (2 * np.pi * f * zeta), t, f_inst)
    near = np.abs(ahead - f) <= 0.5 * zeta * f
    return float(np.max(np.abs(x[near]))) if near.any() else float("nan")


def rig_truth(model: MinistackModel, shaker: Shaker, volts: float, t: NDArray | None = None,
              f_inst: NDArray | None = None, x: NDArray | None = None) -> dict:
    """Truth of one rig run at drive amplitude `volts` (V).

    Parameters
    ----------
    model, shaker, volts : the rig and the amplifier's voltage amplitude (V).
    t, f_inst, x : ndarray, optional
        The simulated sweep: time (s), drive frequency (Hz) and displacement (in), to
        read the amplitude the sweep actually reached near each resonance.

    Returns
    -------
    dict
        q_ss_in, f_hb_hz, zeta_hb: the structure alone (what H1 of response / force
        shows) at the steady-state amplitude at its own phase resonance;
        q_rig_ss_in, f_rig_hz, zeta_rig: the rig's pole (what H1 of response /
        voltage shows) at the steady-state amplitude at the rig's resonance; with the
        sweep, the same at the largest amplitude reached while the drive was within
        +-zeta f / 2 of that resonance (q_reached_in, f_hb_hz_reached, ... a fast chirp
        never builds the steady state), suffixed _reached.
    """
    q_s, q_r = structure_resonance_amplitude(model, shaker, volts), steady_amplitude(model, shaker, volts)
    f, z = structure_equivalent(model, q_s)
    fr, zr = rig_pole(model, shaker, q_r)
    out = dict(q_ss_in=q_s, f_hb_hz=f, zeta_hb=z, q_rig_ss_in=q_r, f_rig_hz=fr, zeta_rig=zr)
    if x is not None:
        qs, qr = _reached(t, f_inst, x, f, z), _reached(t, f_inst, x, fr, zr)
        f2, z2 = structure_equivalent(model, qs)
        fr2, zr2 = rig_pole(model, shaker, qr)
        out.update(q_reached_in=qs, f_hb_hz_reached=f2, zeta_hb_reached=z2, q_rig_reached_in=qr,
                   f_rig_hz_reached=fr2, zeta_rig_reached=zr2)
    return out
