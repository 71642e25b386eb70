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

A second, linear mode of the structure at the driving point (`StructureMode`: natural
frequency, damping, modal weight; its coordinate y, the driving point moving by u = x + y)
puts another resonance in the band and its residual flexibility under the first:

    m x'' + c x' + (k + KT) x + r_nl = F,   m_2 y'' + c_2 y' + k_2 y = F,
    m_a u'' + c_s u' + k_s u = Bl i - F,    L i' + R i + Bl_e u' = V,

with the response accelerometer and the gauge at the driving point (u'', F), a 5-state
system the same kernel integrates.

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

from ..models import MinistackModel, harmonic_balance
from ..models import _integrator
from ..models._masing import kernel_constants
from ..models.iwan import derived
from ..units import G, INCH_M, LBF_N
from ..models.simulate import _substep_maps, band_limited, fractional_delay, hermite_propagator

__all__ = ["Shaker", "StructureMode", "BL_E_PER_BL", "peak_amplitude", "rig_matrices", "simulate_rig", "structure_equivalent", "rig_pole",
           "steady_amplitude", "structure_resonance_amplitude", "rig_truth"]

BL_E_PER_BL = LBF_N * INCH_M  # V/(in/s) of back-EMF per lbf/A of force constant (= 1 in SI)


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


@dataclass(frozen=True)
class StructureMode:
    """A linear mode of the structure at the driving point, beside the jointed one.

    f_hz : natural frequency, Hz.  zeta : damping ratio.  weight_lbf : modal weight at the
    driving point (modal mass x 386.089), lbf.
    """

    f_hz: float
    zeta: float = 0.01
    weight_lbf: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"second_mode.{f.name} must be a positive number, got {v!r}.")

    @property
    def m(self) -> float:
        return self.weight_lbf / G

    @property
    def k(self) -> float:
        return self.m * (2 * np.pi * self.f_hz) ** 2

    @property
    def c(self) -> float:
        return 2 * self.zeta * np.sqrt(self.k * self.m)


def _structure(model: MinistackModel) -> tuple[float, float, float]:
    """Stuck-joint stiffness k + KT (lbf/in), dashpot c (lbf s/in) and mass (lbf s^2/in)."""
    if model.fixture is not None:
        raise ValueError("a shaker rig drives the slug on a rigid base: the fixture_flexibility effect does not apply; "
                         "use reference: base for it.")
    ks = model.k + model.KT
    return ks, 2.0 * model.zeta_v * np.sqrt(ks * model.m), model.m


def rig_matrices(model: MinistackModel, shaker: Shaker, second: StructureMode | None = None):
    """State space of the coupled rig, input V (volts).

    State [x (in), x' (in/s), i (A)], or [x, x', y, y', i] with a second mode.

    Returns
    -------
    A (n, n), bu (n,), bf (n,) : x' = A x + bu V + bf r_nl
    out : dict of (c, du, df) per output, y = c.x + du V + df r_nl:
        'accel' (in/s^2, the driving point) and 'force' (lbf, the gauge).
    """
    ks, c, m = _structure(model)
    Bl, Ble = shaker.bl_lbf_per_A, shaker.bl_lbf_per_A * BL_E_PER_BL
    L, R = shaker.coil_mH * 1e-3, shaker.coil_ohm
    ma = shaker.m_a
    if second is None:
        M, K, C = m + ma, ks + shaker.k_s, c + shaker.c_s
        A = np.array([[0.0, 1.0, 0.0], [-K / M, -C / M, Bl / M], [0.0, -Ble / L, -R / L]])
        bu = np.array([0.0, 0.0, 1.0 / L])
        bf = np.array([0.0, -1.0 / M, 0.0])
        acc = (A[1].copy(), 0.0, -1.0 / M)
        force = (np.array([-shaker.k_s, -shaker.c_s, Bl]) - ma * A[1], 0.0, ma / M)
        return A, bu, bf, {"accel": acc, "force": force}
    # unknowns [x'', y'', F] of: m x'' - F = -(c x' + ks x + r), m2 y'' - F = -(c2 y' + k2 y),
    # m_a (x'' + y'') + F = Bl i - k_s (x + y) - c_s (x' + y'); state [x, x', y, y', i] and r
    M3 = np.array([[m, 0.0, -1.0], [0.0, second.m, -1.0], [ma, ma, 1.0]])
    rhs = np.array([[-ks, -c, 0.0, 0.0, 0.0, -1.0],
                    [0.0, 0.0, -second.k, -second.c, 0.0, 0.0],
                    [-shaker.k_s, -shaker.c_s, -shaker.k_s, -shaker.c_s, Bl, 0.0]])
    sol = np.linalg.solve(M3, rhs)  # rows x'', y'', F as maps of [state, r]
    A = np.zeros((5, 5))
    A[0, 1] = A[2, 3] = 1.0
    A[1], A[3] = sol[0, :5], sol[1, :5]
    A[4] = [0.0, -Ble / L, 0.0, -Ble / L, -R / L]
    bu = np.array([0.0, 0.0, 0.0, 0.0, 1.0 / L])
    bf = np.array([0.0, sol[0, 5], 0.0, sol[1, 5], 0.0])
    acc = (sol[0, :5] + sol[1, :5], 0.0, float(sol[0, 5] + sol[1, 5]))
    force = (sol[2, :5].copy(), 0.0, float(sol[2, 5]))
    return A, bu, bf, {"accel": acc, "force": force}


def simulate_rig(model: MinistackModel, shaker: Shaker, volts: NDArray, fs: float, *, omega_h: float = 0.3,
                 second: StructureMode | None = None):
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
        Largest w_0 h of the integration substeps at the coupled stuck-joint frequency (or
        the second mode's, when higher).
    second : StructureMode, optional
        A second, linear mode at the driving point.

    Returns
    -------
    accel_g, force_lbf, x_in : ndarray, shape (N,)
        The driving point's acceleration and the gauge force; x_in is the jointed mode's
        coordinate x (the driving point's u = x + y with a second mode).
    """
    u = np.ascontiguousarray(volts, dtype=float)
    n_out = u.size
    A, bu, bf, outs = rig_matrices(model, shaker, second)
    ks, _, m = _structure(model)
    w0 = np.sqrt((ks + shaker.k_s) / (m + shaker.m_a))
    if second is not None:
        w0 = max(w0, 2 * np.pi * second.f_hz)
    u, U = band_limited(u, fs, w0 / (2 * np.pi))  # as `simulate` reads its input
    fs = fs * U
    n_sub = max(1, int(np.ceil(w0 / (omega_h * fs))))
    H = 1.0 / fs
    h = H / n_sub
    Phi, Gu = hermite_propagator(A, bu, h)
    _, Gf = hermite_propagator(A, bf, h)
    Gsub, Wub = _substep_maps(Gu, n_sub)
    lz, lv = np.eye(A.shape[0])[0], np.eye(A.shape[0])[1]
    az, bzu, bzf = lv @ A, float(lv @ bu), float(lv @ bf)
    if model.iwan is None:
        joint, KT, R, chi, phimax, Fs = 0, 0.0, 0.0, 0.5, 1.0, 0.0
    else:
        p = model.iwan
        phimax, R, _ = (float(a) for a in derived(p.Fs, p.KT, p.chi, p.beta))
        R, chi = kernel_constants(R, p.chi)
        joint, KT, Fs = 1, p.KT, p.Fs
    res = {}
    for name, (cy, dyu, dyf) in outs.items():  # the same trajectory once per output
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
        f2, z2 = structure_equivalent(model, qs)
        fr2, zr2 = rig_pole(model, shaker, qr, second)
        fs = 1.0 / float(t[1] - t[0])
        out.update(q_reached_in=qs, f_hb_hz_reached=f2, zeta_hb_reached=z2, q_rig_reached_in=qr,
                   f_rig_hz_reached=fr2, zeta_rig_reached=zr2, q_peak_in=peak_amplitude(x, fs, f))
        qx = peak_amplitude(x, fs, fr)
        out["q_rig_peak_in"] = qx * _shape_at_driving_point(model, shaker, qx, second)
    return out
