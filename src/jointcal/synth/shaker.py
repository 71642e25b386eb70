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
remainder r_nl = F_iwan - KT x (and the forces of the model's elements) enters as in
`jointcal.models.simulate`, whose exact-Iwan kernel integrates this 3-state system.

A second, linear mode of the structure at the driving point (`StructureMode`: natural
frequency, damping, modal weight; its coordinate y, the driving point moving by u = x + y)
puts another resonance in the band and its residual flexibility under the first:

    m x'' + c x' + (k + KT) x + r_nl = F,   m_2 y'' + c_2 y' + k_2 y = F,
    m_a u'' + c_s u' + k_s u = Bl i - F,    L i' + R i + Bl_e u' = V,

with the response accelerometer and the gauge at the driving point (u'', F), a 5-state
system the same kernel integrates.

A second mode may carry its own Iwan joint (`StructureMode.iwan`: m_2 y'' + c_2 y' + k_2 y
+ r_nl,2 = F, k_2 the stuck stiffness, r_nl,2 = F_iwan,2(y) - KT_2 y): two jointed modes the
coil's back-EMF and the armature couple, so they are not integrated apart; the 5-state
system is then integrated with a joint on each of x and y
(`jointcal.models.joints.integrate_joints`, the same exact Iwan force law and scheme).

The rig's truth at a drive level (what its FRFs show) is `jointcal.synth.rig_truth`.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import NDArray

from ..models import IwanParams, MinistackModel
from ..units import G, INCH_M, LBF_N
from ..models.joints import integrate_joints
from ..models.simulate import band_limited, fractional_delay, integrate
from ..models.structure import StateSpace

__all__ = ["Shaker", "StructureMode", "BL_E_PER_BL", "rig_matrices", "rig_joint_matrices", "simulate_rig"]

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
    driving point (modal mass x 386.089), lbf.  iwan : optional Iwan joint of the mode; then
    f_hz and zeta are the mode's with the joint stuck (its spring k - KT in parallel with the
    joint, as `MinistackModel`'s k and KT), and the mode softens and damps with amplitude.
    """

    f_hz: float
    zeta: float = 0.01
    weight_lbf: float = 1.0
    iwan: IwanParams | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "iwan":
                continue
            v = getattr(self, f.name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"second_mode.{f.name} must be a positive number, got {v!r}.")
        if self.iwan is not None and not self.iwan.KT < self.k:
            raise ValueError(f"second_mode: the joint's KT ({self.iwan.KT!r} lbf/in) must be below the mode's stuck "
                             f"stiffness m (2 pi f)^2 = {self.k:.6g} lbf/in.")

    @property
    def m(self) -> float:
        return self.weight_lbf / G

    @property
    def k(self) -> float:
        return self.m * (2 * np.pi * self.f_hz) ** 2

    @property
    def c(self) -> float:
        return 2 * self.zeta * np.sqrt(self.k * self.m)

    def model(self) -> MinistackModel:
        """The mode as a `MinistackModel` on a rigid base (spring k - KT, its joint, zeta at the stuck frequency)."""
        KT = 0.0 if self.iwan is None else self.iwan.KT
        return MinistackModel(m=self.m, k=self.k - KT, zeta_v=self.zeta, iwan=self.iwan)


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
        The second mode's joint remainder, if any, is in `rig_joint_matrices`.
    """
    if second is None:
        return _rig3(model, shaker)
    A, bu, BF, outs = rig_joint_matrices(model, shaker, second)
    return A, bu, BF[:, 0].copy(), {k: (c, du, float(df[0])) for k, (c, du, df) in outs.items()}


def _rig3(model: MinistackModel, shaker: Shaker):
    """The 3-state rig of `rig_matrices` (one mode)."""
    ks, c, m = _structure(model)
    Bl, Ble = shaker.bl_lbf_per_A, shaker.bl_lbf_per_A * BL_E_PER_BL
    L, R = shaker.coil_mH * 1e-3, shaker.coil_ohm
    ma = shaker.m_a
    M, K, C = m + ma, ks + shaker.k_s, c + shaker.c_s
    A = np.array([[0.0, 1.0, 0.0], [-K / M, -C / M, Bl / M], [0.0, -Ble / L, -R / L]])
    bu = np.array([0.0, 0.0, 1.0 / L])
    bf = np.array([0.0, -1.0 / M, 0.0])
    acc = (A[1].copy(), 0.0, -1.0 / M)
    force = (np.array([-shaker.k_s, -shaker.c_s, Bl]) - ma * A[1], 0.0, ma / M)
    return A, bu, bf, {"accel": acc, "force": force}


def rig_joint_matrices(model: MinistackModel, shaker: Shaker, second: StructureMode):
    """The 5-state rig with a second mode, each mode's joint remainder a separate input.

    State [x, x', y, y', i] (in, in/s, in, in/s, A); r = [r_nl (the jointed mode's), r_nl,2
    (the second mode's joint; zero if it has none)], lbf.

    Returns
    -------
    A (5, 5), bu (5,), BF (5, 2) : x' = A x + bu V + BF r
    out : dict of (c (5,), du, df (2,)) per output, y = c.x + du V + df.r: 'accel' (in/s^2, the
        driving point u'' = x'' + y'') and 'force' (lbf, the gauge).
    """
    ks, c, m = _structure(model)
    Bl, Ble = shaker.bl_lbf_per_A, shaker.bl_lbf_per_A * BL_E_PER_BL
    L, R = shaker.coil_mH * 1e-3, shaker.coil_ohm
    ma = shaker.m_a
    # unknowns [x'', y'', F] of: m x'' - F = -(c x' + ks x + r), m2 y'' - F = -(c2 y' + k2 y + r2),
    # m_a (x'' + y'') + F = Bl i - k_s (x + y) - c_s (x' + y'); state [x, x', y, y', i] and [r, r2]
    M3 = np.array([[m, 0.0, -1.0], [0.0, second.m, -1.0], [ma, ma, 1.0]])
    rhs = np.array([[-ks, -c, 0.0, 0.0, 0.0, -1.0, 0.0],
                    [0.0, 0.0, -second.k, -second.c, 0.0, 0.0, -1.0],
                    [-shaker.k_s, -shaker.c_s, -shaker.k_s, -shaker.c_s, Bl, 0.0, 0.0]])
    sol = np.linalg.solve(M3, rhs)  # rows x'', y'', F as maps of [state, r, r2]
    A = np.zeros((5, 5))
    A[0, 1] = A[2, 3] = 1.0
    A[1], A[3] = sol[0, :5], sol[1, :5]
    A[4] = [0.0, -Ble / L, 0.0, -Ble / L, -R / L]
    bu = np.array([0.0, 0.0, 0.0, 0.0, 1.0 / L])
    BF = np.zeros((5, 2))
    BF[1], BF[3] = sol[0, 5:], sol[1, 5:]
    acc = (sol[0, :5] + sol[1, :5], 0.0, sol[0, 5:] + sol[1, 5:])
    force = (sol[2, :5].copy(), 0.0, sol[2, 5:].copy())
    return A, bu, BF, {"accel": acc, "force": force}


def simulate_rig(model: MinistackModel, shaker: Shaker, volts: NDArray, fs: float, *, omega_h: float = 0.3,
                 second: StructureMode | None = None, coordinates: bool = False):
    """Response acceleration (g), gauge force (lbf) and displacement (in) under a drive voltage.

    Parameters
    ----------
    model : MinistackModel
        The structure (joint, k, zeta_v, mass; its elements, sensor_gain and
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
        A second mode at the driving point, linear or with its own Iwan joint.
    coordinates : bool
        Also return the second mode's coordinate y.

    Returns
    -------
    accel_g, force_lbf, x_in : ndarray, shape (N,)
        The driving point's acceleration and the gauge force; x_in is the jointed mode's
        coordinate x (the driving point's u = x + y with a second mode).
    y_in : ndarray, shape (N,)
        With `coordinates`: the second mode's coordinate y, in (zeros without one).
    """
    u = np.ascontiguousarray(volts, dtype=float)
    n_out = u.size
    ks, _, m = _structure(model)
    w0 = np.sqrt((ks + shaker.k_s) / (m + shaker.m_a))
    if second is not None:
        w0 = max(w0, 2 * np.pi * second.f_hz)
    u, U = band_limited(u, fs, w0 / (2 * np.pi))  # as `simulate` reads its input
    fs = fs * U
    n_sub = max(1, int(np.ceil(w0 / (omega_h * fs))))
    if second is not None and second.iwan is not None:
        if model.elements:
            raise ValueError("simulate_rig: a jointed second mode takes an exact Iwan joint on each mode and no "
                             f"elements; the model has {len(model.elements)}.")
        A, bu, BF, outs = rig_joint_matrices(model, shaker, second)
        outs = {**outs, "y": (np.eye(5)[2], 0.0, np.zeros(2))}
        Y, Z = integrate_joints(A, bu, BF, np.eye(5)[[0, 2]], np.eye(5)[[1, 3]], u, fs, n_sub,
                                [model.iwan, second.iwan], list(outs.values()))
        x = Z[0]
    else:
        A, bu, bf, outs = rig_matrices(model, shaker, second)
        n = A.shape[0]
        if coordinates:
            outs = {**outs, "y": (np.eye(n)[2] if second is not None else np.zeros(n), 0.0, 0.0)}
        lz, lv = np.eye(n)[0], np.eye(n)[1]
        ss = StateSpace(A, bu, bf, *outs["accel"], lz, lv)
        Y, x = integrate(ss, u, fs, n_sub, iwan=model.iwan, elements=model.elements, outputs=list(outs.values()))
    res = {name: y[::U][:n_out].copy() for name, y in zip(outs, Y)}
    x = x[::U][:n_out].copy()
    fs = fs / U
    acc = res["accel"]
    if model.sensor_delay_s != 0.0:
        acc = fractional_delay(acc, model.sensor_delay_s, fs)
    if coordinates:
        return acc * model.sensor_gain / G, res["force"], x, res["y"]
    return acc * model.sensor_gain / G, res["force"], x
