"""Linear structure of the base-excited Ministack model, and its named effects.

The slug (mass m) sits on a linear spring k in parallel with the Iwan joint and a
dashpot c = 2 zeta_v sqrt((k + KT) m) (zeta_v is the viscous ratio at the stuck-joint
frequency). Coordinates are relative to the control accelerometer (the base):

* no fixture:  q = [z],        z = x_slug - x_base;
* fixture:     q = [w, z],     w = x_can - x_base, z = x_slug - x_can: the can (mass
  m_can on a spring of own frequency f_can, ratio zeta_can) is an extra DOF between
  the control accelerometer and the joint, loaded by the slug.

M q'' + C q' + K q = -M_b a_base - e_z r_nl, where K holds the STUCK joint stiffness
KT and r_nl is the nonlinear remainder of the joint restoring force,
r_nl = F_iwan(z) - KT z + the forces of `elements` (`jointcal.models.elements`: a cubic
spring, a quadratic damper, a contact spring). The response channel is the slug's
absolute acceleration a_base + s.q''. An effect changes the model through these fields
(`jointcal.effects`): a linear one through the structure (`fixture`, assembled in
`state_space`), a nonlinear one by adding an element (the kernels read the element
table: a new kind of element is one inline function in each kernel, and no change of
their signatures), a sensor one (gain, delay) on the output channel after integration.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .elements import Element
from .iwan import IwanParams

__all__ = ["Neighbour", "Fixture", "can_spring", "MinistackModel", "StateSpace", "state_space"]


@dataclass(frozen=True)
class Fixture:
    """Flexible can between the control accelerometer and the joint.

    m_can : moving mass of the can, lbf s^2/in; f_can : its own frequency on its
    spring with the slug removed, Hz; zeta_can : its viscous damping ratio.
    """

    m_can: float
    f_can: float
    zeta_can: float = 0.01


def can_spring(m_can: ArrayLike, f_can: ArrayLike,
               zeta_can: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The fixture can's spring k_can = m_can (2 pi f_can)^2 (lbf/in) and dashpot c_can = 2 zeta_can sqrt(k_can m_can).

    Parameters
    ----------
    m_can, f_can, zeta_can : float or array_like, broadcast together
        The can's moving mass (lbf s^2/in), its own frequency on its spring with the slug
        removed (Hz) and its viscous damping ratio (`Fixture`), one per parameter set.

    Returns
    -------
    k_can, c_can : ndarray
        Stiffness (lbf/in) and dashpot (lbf s/in), of the broadcast shape.
    """
    k_can = m_can * (2 * np.pi * f_can) ** 2
    return k_can, 2.0 * zeta_can * np.sqrt(k_can * m_can)


@dataclass(frozen=True)
class Neighbour:
    """A linear mode beside the modelled one that the response channel also sees, driven by the same input.

    Its relative acceleration per unit base acceleration is ``ratio`` w^2 / (w_n^2 - w^2 + 2 i zeta w_n w),
    w_n = 2 pi ``f_hz``: the modelled mode's own form with ``ratio`` times its modal constant (a residual
    mode above the band reads as a mass line, one below as a stiffness line). Fields may be batched (P, 1).

    On a voltage drive the shaker's armature and back-EMF load the driving point, and so the
    neighbour's motion as well as the mode's: the neighbour is then not a term added to the
    response. With the sensor at the driving point, both modes' accelerations in units of the
    drive (N' = `frf`, T_s the mode alone), the shaker's loop adds c' to the inverse of their sum,

        Y / e = 1 / (1 / (T_s + N') + c'),    c' = -``armature`` + i ``back_emf`` w_r / w,  (N1)

    ``armature`` the armature's share of the loaded mode's mass and ``back_emf`` the back-EMF's
    damping 2 zeta_e at w_r = 2 pi ``f_ref_hz`` (the coil's own lag, x = w L / R, is left out: x^2
    under 1% on the rigs read so far). The mode the calibration holds is already the loaded one,
    1 / T = 1 / T_s + c', so (N1) is that mode with an added dynamic stiffness and drive
    (`loop`), exact at the mode's amplitude for a nonlinear joint too. Both zero (a force drive:
    the gauge measures the force, the shaker is outside the FRF): (N1) is T + N'.

    The drive e is the read-out's, the campaign's modal constant from a one-mode fit of each record
    (`jointcal.validate.drive`). Beside a looped neighbour that fit reads the wrong constant (the
    jointed beam's voltage rig with a second mode at 150 Hz: 32% high, 4 deg), so the mode's own drive
    is e / kappa, kappa = ``read_gain`` exp(i ``read_phase``) the read-out's constant over the mode's.

    Parameters
    ----------
    f_hz : float
        Its natural frequency, Hz.
    ratio : float
        Its modal constant over the modelled mode's (signed, -).
    zeta : float
        Its damping ratio.
    armature, back_emf : float
        The shaker loop's constants of (N1), - (0: no loop).
    f_ref_hz : float
        Where ``back_emf`` is taken, Hz (the mode's stuck-joint frequency).
    read_gain, read_phase : float
        kappa's magnitude (-) and phase (rad): the read-out's drive constant over the mode's own.
    """

    f_hz: float
    ratio: float
    zeta: float = 0.01
    armature: float = 0.0
    back_emf: float = 0.0
    f_ref_hz: float = 1.0
    read_gain: float = 1.0
    read_phase: float = 0.0

    def frf(self, f: NDArray) -> NDArray[np.complex128]:
        """Relative acceleration over base acceleration at frequencies f (Hz), shape broadcast(fields, f)."""
        wn, w = 2 * np.pi * np.asarray(self.f_hz, float), 2 * np.pi * np.asarray(f, float)
        return np.asarray(self.ratio, float) * w**2 / (wn**2 - w**2 + 2j * np.asarray(self.zeta, float) * wn * w)

    @property
    def looped(self) -> bool:
        """Whether the shaker's loop (N1) acts or the read-out's constant is not the mode's (a voltage drive)."""
        return bool(np.any(np.asarray(self.armature) != 0) or np.any(np.asarray(self.back_emf) != 0)
                    or np.any(np.asarray(self.read_gain) != 1) or np.any(np.asarray(self.read_phase) != 0))

    def batched(self, field: Callable[[ArrayLike], NDArray]) -> Neighbour:
        """The same neighbour with each field passed through `field` (e.g. broadcast to a batch (P, 1))."""
        return Neighbour(*(field(getattr(self, f.name)) for f in fields(self)))

    @property
    def kappa(self) -> NDArray[np.complex128]:
        """The read-out's drive constant over the mode's own, read_gain exp(i read_phase)."""
        return np.asarray(self.read_gain, float) * np.exp(1j * np.asarray(self.read_phase, float))

    def loop(self, f: NDArray) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """The loaded mode's drive factor gamma and added dynamic stiffness delta of (N1) at f (Hz).

        With T the loaded mode's relative acceleration (the calibration's) driven by gamma e / kappa and
        with its inverse 1 / T = (K_z - m w^2) / (m w^2) raised by delta (an added stiffness delta m w^2),

            gamma = 1 / (1 + c' N'),  delta = -c'^2 N' / (1 + c' N'),  Y / e = gamma (T + N' / kappa).  (N2)

        Returns
        -------
        gamma, delta : ndarray of complex, shape broadcast(fields, f)
        """
        f = np.asarray(f, float)
        c = -np.asarray(self.armature, float) + 1j * np.asarray(self.back_emf, float) * np.asarray(self.f_ref_hz,
                                                                                                     float) / f
        cn = c * self.frf(f)
        return 1.0 / (1.0 + cn), -c * cn / (1.0 + cn)


@dataclass(frozen=True)
class MinistackModel:
    """Slug on a spring k in parallel with an Iwan joint, base excited.

    Parameters
    ----------
    m : float
        Slug mass, lbf s^2/in (weight / 386.089).
    k : float
        Linear spring in parallel with the joint, lbf/in.
    zeta_v : float
        Viscous damping ratio at the stuck-joint frequency sqrt((k + KT)/m).
    iwan : IwanParams or None
        The joint; None gives the linear model with stiffness k.
    fixture : Fixture or None
        Flexible can DOF (named effect ``fixture_flexibility``).
    elements : tuple of Element
        Nonlinear elements in parallel with the joint (`jointcal.models.elements`): a cubic
        spring (``cubic_stiffening``), a quadratic damper (``quadratic_damping``), a
        unilateral contact spring (a stop, a bottomed foam cup: only the time simulation
        models it).
    sensor_gain : float
        Response-channel sensitivity error factor (``sensor_gain``).
    sensor_delay_s : float
        Response-channel delay, s (``channel_delay``).
    neighbour : Neighbour or None
        A linear mode beside this one that the response channel also sees (``neighbour_mode``).
    """

    m: float
    k: float
    zeta_v: float
    iwan: IwanParams | None = None
    fixture: Fixture | None = None
    elements: tuple[Element, ...] = ()
    sensor_gain: float = 1.0
    sensor_delay_s: float = 0.0
    neighbour: Neighbour | None = None

    def __post_init__(self) -> None:
        for name in ("m", "k"):
            v = getattr(self, name)
            if not np.all(np.isfinite(v) & (np.asarray(v) > 0)):  # arrays: a batch of parameter sets
                raise ValueError(f"MinistackModel.{name} must be positive and finite, got {v!r}.")
        if not np.all((np.asarray(self.zeta_v) >= 0) & (np.asarray(self.zeta_v) < 1)):
            raise ValueError(f"MinistackModel.zeta_v must lie in [0, 1), got {self.zeta_v!r}.")
        if not np.all(np.asarray(self.sensor_gain) > 0):
            raise ValueError(f"sensor_gain must be positive, got {self.sensor_gain!r}.")
        if not all(isinstance(e, Element) for e in self.elements):
            raise ValueError(f"MinistackModel.elements must be a tuple of Element, got {self.elements!r}.")

    @property
    def KT(self) -> float:
        """Stuck joint stiffness, lbf/in (0 without a joint)."""
        return 0.0 if self.iwan is None else self.iwan.KT

    @property
    def f0_hz(self) -> float:
        """Stuck-joint natural frequency of the slug on a rigid base, Hz."""
        return float(np.sqrt((self.k + self.KT) / self.m) / (2 * np.pi))


@dataclass(frozen=True)
class StateSpace:
    """x' = A x + bu u + bf r_nl; y = cy.x + dyu u + dyf r_nl; z = lz.x, z' = lv.x."""

    A: np.ndarray
    bu: np.ndarray
    bf: np.ndarray
    cy: np.ndarray
    dyu: float
    dyf: float
    lz: np.ndarray
    lv: np.ndarray
    extra: dict = field(default_factory=dict)


def _loop_matrices(model: MinistackModel, ks: float, c: float) -> tuple[NDArray, ...]:
    """M, C, K, the drive's Mb and the joint's ez of the mode (relative z) and its neighbour (relative y) in a
    voltage drive's shaker loop (`Neighbour`, (N1)), both driven by F = u + mu_a (z'' + y'') + beta w_r (z' + y')
    (the loop's c' in time: c' a = -mu_a a + beta w_r v):

        m z'' + c z' + K z + r_nl = -m u - m (mu_a y'' + beta w_r y')      (the calibrated, loaded mode)
        y'' + 2 zeta_n w_n y' + w_n^2 y = -r F                               (the neighbour, ratio r)

    The first row is the loaded mode's: its mass and dashpot hold the armature and back-EMF acting on its
    own motion (1 / T = 1 / T_s + c'), and the loop couples it to the neighbour's. u is the mode's own
    drive, the read-out's over kappa (`Neighbour.kappa`; `simulate` turns the record)."""
    if model.fixture is not None:
        raise ValueError("a neighbouring mode in a shaker's loop is a voltage-driven structure's (the modal model "
                         "kind); the Ministack's fixture model has no such loop.")
    nb, m = model.neighbour, model.m
    wn, wr = 2 * np.pi * float(nb.f_hz), 2 * np.pi * float(nb.f_ref_hz)
    r, mu, b = float(nb.ratio), float(nb.armature), float(nb.back_emf) * wr
    M = np.array([[m, m * mu], [r * mu, 1.0 + r * mu]])
    C = np.array([[c, m * b], [r * b, 2 * float(nb.zeta) * wn + r * b]])
    K = np.diag([ks, wn**2])
    Minv = np.linalg.inv(M)
    poles = np.linalg.eigvals(np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ C]]))
    if np.any(poles.real > 0):
        raise ValueError(f"the neighbour's shaker loop (armature {mu:g}, back-EMF 2 zeta_e {float(nb.back_emf):g}, "
                         f"ratio {r:g}) makes the stuck model unstable: the back-EMF must not exceed the mode's own "
                         "viscous damping (2 zeta_v), the armature's share and the ratio must lie in [0, 1) and >= 0.")
    return M, C, K, np.array([m, r]), np.array([1.0, 0.0])


def state_space(model: MinistackModel) -> StateSpace:
    """Assemble the first-order linear system with the joint stuck (stiffness k + KT)."""
    m, ks = model.m, model.k + model.KT
    c = 2.0 * model.zeta_v * np.sqrt(ks * m)
    nb = model.neighbour
    if nb is not None and nb.looped:
        M, C, K, Mb, ez = _loop_matrices(model, ks, c)
    elif model.fixture is None:
        M = np.array([[m]])
        K = np.array([[ks]])
        C = np.array([[c]])
        Mb = np.array([m])
        ez = np.array([1.0])
    else:
        fx = model.fixture
        k_can, c_can = can_spring(fx.m_can, fx.f_can, fx.zeta_can)
        M = np.array([[fx.m_can + m, m], [m, m]])
        K = np.diag([k_can, ks])
        C = np.diag([c_can, c])
        Mb = np.array([fx.m_can + m, m])
        ez = np.array([0.0, 1.0])
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Minv @ K
    A[n:, n:] = -Minv @ C
    bu = np.concatenate([np.zeros(n), -Minv @ Mb])
    bf = np.concatenate([np.zeros(n), -Minv @ ez])
    s = np.ones(n)  # slug absolute acceleration = a_base + sum of relative accelerations
    cy = s @ A[n:]
    dyu = 1.0 + s @ bu[n:]
    dyf = s @ bf[n:]
    lz = np.concatenate([ez, np.zeros(n)])
    lv = np.concatenate([np.zeros(n), ez])
    return StateSpace(A, bu, bf, cy, float(dyu), float(dyf), lz, lv)
