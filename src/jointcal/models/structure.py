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

from dataclasses import dataclass, field

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

    Parameters
    ----------
    f_hz : float
        Its natural frequency, Hz.
    ratio : float
        Its modal constant over the modelled mode's (signed, -).
    zeta : float
        Its damping ratio.
    """

    f_hz: float
    ratio: float
    zeta: float = 0.01

    def frf(self, f: NDArray) -> NDArray[np.complex128]:
        """Relative acceleration over base acceleration at frequencies f (Hz), shape broadcast(fields, f)."""
        wn, w = 2 * np.pi * np.asarray(self.f_hz, float), 2 * np.pi * np.asarray(f, float)
        return np.asarray(self.ratio, float) * w**2 / (wn**2 - w**2 + 2j * np.asarray(self.zeta, float) * wn * w)


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


def state_space(model: MinistackModel) -> StateSpace:
    """Assemble the first-order linear system with the joint stuck (stiffness k + KT)."""
    m, ks = model.m, model.k + model.KT
    c = 2.0 * model.zeta_v * np.sqrt(ks * m)
    if model.fixture is None:
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
