"""Steady-state envelope of a swept-sine test: the first-harmonic (describing-function) model.

At each drive frequency f the base acceleration is a_b = A cos(omega t) and the joint
moves as z = Re(Z e^{i omega t}), |Z| = q. Every nonlinear element of the joint DOF is
replaced by its describing function at q (docs/physics.md, sections 2 and 7):

* Iwan joint (eqs. 3.3-3.7): in-phase stiffness KT - R q^(chi+1) J - S (1 - g(phi_max/q))
  (the last term past macroslip) and energy-equivalent damping, i omega c_eq with
  omega c_eq = D(q) / (pi q^2);
* elements (`jointcal.models.elements`): cubic spring a z^3, + 3/4 a q^2; quadratic damper
  a z'|z'|, omega c_eq = 8 a omega^2 q / (3 pi);
* linear spring k and dashpot c = 2 zeta_v sqrt((k + KT) m).

The structure around the joint DOF is linear and exact: on a rigid base
Z = -m A / (K_z(q) - m omega^2); with the flexible fixture (`Fixture`, coordinates of
`state_space`) the can's DOF is condensed exactly, Z = -gamma m A / (K_z(q) - mu) with a
complex effective inertia mu and base-load factor gamma. So q solves the scalar fixed
point q = |gamma| m A / |K_z(q) - mu|, up to three solutions near a softening fold (two
stable). The measured channel is the slug's absolute acceleration through the sensor:
T = gain * (1 - omega^2 (W + Z) / A) * exp(-i omega tau).

Every named effect (`jointcal.effects`) enters here and in the time integrator from the
same fields of `MinistackModel`: the structure (`_structure_terms`), the sensor, and the
element table of the joint DOF (`jointcal.models.elements`), whose describing functions
are inline functions of `_envelope_kernel` (one per kind of element).

The swept models (`jointcal.models.swept`, `jointcal.models.swept_integrated`) build on the
same batch: `batch_shape` and `batch_field` (a model's fields over P parameter sets),
`joint_terms` (the kernels' joint parameters), `sweep_amplitudes` (the continuation along a
sweep) and the quadrature `GAUSS_NODES`, `GAUSS_WEIGHTS`.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields as dataclass_fields
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _envelope_kernel as _k
from ..units import G
from .amplitude import _J
from .elements import FIRST_HARMONIC, NAMES, element_table
from .iwan import derived
from .structure import MinistackModel, Neighbour, can_spring

__all__ = ["SteadyState", "steady_state", "batch_shape", "batch_field", "joint_terms", "sweep_amplitudes",
           "GAUSS_NODES", "GAUSS_WEIGHTS"]

_X, _W = np.polynomial.legendre.leggauss(16)
GAUSS_NODES, GAUSS_WEIGHTS = 0.5 * (_X + 1.0), 0.5 * _W  # 16-point Gauss-Legendre on [0, 1], the kernels' quadrature
TOL = 1e-10  # convergence of s = log q: 1e-10 relative in amplitude


@dataclass(frozen=True)
class SteadyState:
    """Steady-state first-harmonic response along a sweep.

    Attributes
    ----------
    transmissibility : ndarray of complex, shape (..., N)
        Measured response channel over base acceleration (sensor gain and delay
        applied), the envelope a swept-sine test shows (dimensionless).
    relative : ndarray of complex, shape (..., N)
        Joint relative displacement Z (in) per unit phase of the base acceleration
        (z = Re(Z e^{i omega t}) when a_b = A cos(omega t)).
    q_in : ndarray, shape (..., N)
        Joint amplitude |Z|, in.
    jump : ndarray of bool, shape (..., N)
        True at the first frequency (in sweep order) after the followed branch ended
        at a fold: the response jumps there.
    """

    transmissibility: NDArray[np.complex128]
    relative: NDArray[np.complex128]
    q_in: NDArray[np.float64]
    jump: NDArray[np.bool_]


def batch_field(value, shape) -> NDArray[np.float64]:
    """A model field broadcast to the parameter batch (P,) (constant along frequency).

    Always a new C-contiguous, writeable array: a read-only broadcast view would compile the kernels
    again for read-only arguments."""
    a = np.broadcast_to(np.asarray(value, dtype=float), shape)
    return np.array(a.reshape(-1, shape[-1])[:, 0], dtype=float, order="C")


def batch_shape(model: MinistackModel, f_shape: tuple) -> tuple[tuple[int, int], tuple]:
    """(P, N) of a model's parameter batch along frequencies of shape f_shape, and the broadcast output shape."""
    iw = model.iwan
    fields = [model.m, model.k, model.zeta_v, model.sensor_gain, model.sensor_delay_s]
    fields += [v for e in model.elements for v in (e.a, e.b)]
    if iw is not None:
        fields += [iw.Fs, iw.KT, iw.chi, iw.beta]
    if model.fixture is not None:
        fields += [model.fixture.m_can, model.fixture.f_can, model.fixture.zeta_can]
    if model.neighbour is not None:
        fields += [getattr(model.neighbour, f.name) for f in dataclass_fields(model.neighbour)]
    out_shape = np.broadcast_shapes(*(np.shape(v) for v in fields), f_shape)
    return (int(np.prod(out_shape[:-1], dtype=int)), out_shape[-1]), out_shape


def joint_terms(model: MinistackModel, shape) -> tuple[NDArray, ...]:
    """The joint DOF's kernel parameters: k, c, KT, R, chi, phi_max, S, J(chi, 1), each (P,), and the
    element table: codes (n_e,), coefficients (P, n_e, 2).

    c = 2 zeta_v sqrt((k + KT) m) is the dashpot (lbf s/in); R, S, phi_max the Iwan density
    parameters (`iwan.derived`); a linear model has KT = 0.
    """
    P = shape[0]
    m, k, zv = (batch_field(v, shape) for v in (model.m, model.k, model.zeta_v))
    codes, coefs = element_table(model.elements, lambda v: batch_field(v, shape))
    iw = model.iwan
    if iw is None:
        KT = np.zeros(P)
        R = S = J1 = np.zeros(P)
        chi = np.full(P, -0.5)
        phimax = np.ones(P)
    else:
        Fs, KT, chi, beta = (batch_field(v, shape) for v in (iw.Fs, iw.KT, iw.chi, iw.beta))
        phimax, R, S = derived(Fs, KT, chi, beta)
        J1 = _J(chi, np.ones_like(chi))
    c = 2.0 * zv * np.sqrt((k + KT) * m)
    return k, c, KT, R, chi, phimax, S, J1, codes, coefs


def sweep_amplitudes(f: NDArray, A: NDArray, direction: str, shape, joint, m: NDArray, mu: NDArray,
                     gamma: NDArray | None, segments: Sequence[tuple[int, int, str]] | None = None
                     ) -> tuple[NDArray, ...]:
    """The kernel's continuation along the sweep: s = log q, jump flags and K_z = kre + i kim, each (P, N).

    joint : `joint_terms`; m (P,); mu (P, N) and gamma (P, N) or None (rigid base) from
    `_structure_terms`; A (N,) base amplitude, in/s^2. segments : (start, stop, direction) of several runs laid
    end to end along f, each continued on its own as a run alone would be, in one call of the kernel (direction
    is then unused); None: f is one run.
    """
    P = shape[0]
    w = 2 * np.pi * f
    k, c, KT, R, chi, phimax, S, J1, codes, coefs = joint
    rigid = gamma is None
    logB = np.log(m[:, None] * A) + (0.0 if rigid else np.log(np.abs(gamma)))
    segments = [(0, f.size, direction)] if segments is None else segments
    orders, s_start = [], np.empty((len(segments), P))
    for g, (a, b, way) in enumerate(segments):  # each segment's sweep order and start, as a run alone
        order = np.argsort(f[a:b], kind="stable")
        if way == "down":
            order = order[::-1]
        n0 = order[0] + a
        stuck = k + KT + 1j * w[n0] * c
        g0 = 1.0 if rigid else np.abs(gamma[:, n0])
        s_start[g] = np.log(g0 * m * A[n0] / np.abs(stuck - mu[:, n0]))
        orders.append(order + a)
    bounds = np.array([0, *np.cumsum([b - a for a, b, _ in segments])], dtype=np.int64)
    s = np.empty((P, f.size))
    jump = np.zeros((P, f.size), dtype=np.bool_)
    kre, kim = np.empty((P, f.size)), np.empty((P, f.size))
    solver = _k.solve_parallel if P >= 64 else _k.solve  # threads pay off only for large batches
    mu_re = np.ascontiguousarray(mu.real)
    mu_im = np.zeros_like(mu_re) if rigid else np.ascontiguousarray(mu.imag)
    solver(w, mu_re, mu_im, np.ascontiguousarray(np.broadcast_to(logB, (P, f.size))), s_start,
           np.concatenate(orders).astype(np.int64), bounds, k, c, KT, R, chi, phimax, S, J1, codes, coefs,
           GAUSS_NODES, GAUSS_WEIGHTS, TOL, s, jump, kre, kim)
    return s, jump, kre, kim


def _structure_terms(model: MinistackModel, w: NDArray, shape) -> tuple[NDArray, NDArray]:
    """Effective inertia mu (P, N) and base-load factor gamma (P, N) seen by the joint DOF.

    Rigid base: mu = m omega^2, gamma = 1. Fixture (can DOF w = x_can - x_base between the
    base and the joint; M = [[m_can + m, m], [m, m]], K = diag(k_can, K_z)): condensing
    the can's row, a11 = k_can + i omega c_can - omega^2 (m_can + m), gives
    mu = omega^2 m (1 + omega^2 m / a11) and gamma = (k_can + i omega c_can) / a11. A voltage
    drive's shaker loop around a neighbouring mode (`Neighbour.loop`, (N2)): mu = m omega^2
    (1 - delta) and gamma = gamma_loop / kappa.
    """
    m = batch_field(model.m, shape)[:, None]
    nb = model.neighbour
    if nb is not None and nb.looped:  # a voltage drive's shaker loop around the neighbour (`Neighbour.loop`, (N2))
        if model.fixture is not None:
            raise ValueError("a neighbouring mode in a shaker's loop is a voltage-driven structure's (the modal "
                             "model kind); the Ministack's fixture model has no such loop.")
        nb = nb.batched(lambda v: batch_field(v, shape)[:, None])
        gamma, delta = nb.loop(w / (2 * np.pi))
        return m * w**2 * (1.0 - delta), gamma / nb.kappa  # the drive factor g of F = -g m
    if model.fixture is None:
        return m * w**2, None  # real inertia, unit load factor
    fx = model.fixture
    m_can = batch_field(fx.m_can, shape)[:, None]
    k_can, c_can = can_spring(m_can, batch_field(fx.f_can, shape)[:, None], batch_field(fx.zeta_can, shape)[:, None])
    kc = k_can + 1j * w * c_can
    a11 = kc - w**2 * (m_can + m)
    return w**2 * m * (1.0 + w**2 * m / a11), kc / a11


def _checked(model: MinistackModel, f_hz: ArrayLike, base_g: ArrayLike, direction: str) -> tuple[NDArray, NDArray]:
    """Frequencies f (N,), Hz, and base amplitudes A (N,), in/s^2; one sentence for each bad input."""
    if direction not in ("up", "down"):
        raise ValueError(f"direction must be 'up' or 'down', got {direction!r}.")
    f = np.atleast_1d(np.asarray(f_hz, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f) & (f > 0)):
        raise ValueError("steady_state: f_hz must be a 1-D array of positive, finite frequencies in Hz.")
    A = np.broadcast_to(np.asarray(base_g, dtype=float), f.shape) * G
    if not np.all(np.isfinite(A) & (A > 0)):
        raise ValueError("steady_state: base_g must be positive and finite (g) at every frequency.")
    other = [NAMES[e.code] for e in model.elements if e.code not in FIRST_HARMONIC]
    if other:
        raise ValueError(f"steady_state has no first-harmonic model of a {', '.join(other)} (a unilateral contact: "
                         "its response has a mean offset and even harmonics); use jointcal.models.simulate.")
    return f, A


def steady_state(model: MinistackModel, f_hz: ArrayLike, base_g: ArrayLike = 1.0, *,
                 direction: Literal["up", "down"] = "up") -> SteadyState:
    """Steady-state first-harmonic response of a base-excited model along a sweep.

    Parameters
    ----------
    model : MinistackModel
        Structure, joint and named effects. Its numeric fields (and those of its
        `IwanParams` and `Fixture`) may be arrays of shape (P, 1) (or (P1, P2, 1), ...)
        to evaluate P parameter sets at once; they must not vary along the last
        (frequency) axis.
    f_hz : array_like, shape (N,)
        Drive frequencies, Hz (> 0), in any order; the sweep order is set by `direction`.
    base_g : float or array_like, shape (N,)
        Base-acceleration amplitude at each frequency, g (e.g. the measured base envelope).
    direction : {'up', 'down'}
        Sweep direction: where the response has several stable amplitudes, the one a
        sweep reaches, i.e. the branch continued from the sweep's start until it ends
        at a fold (flagged in `jump`).

    Returns
    -------
    SteadyState
        Arrays of shape broadcast(parameter shape, (N,)).

    Notes
    -----
    Each amplitude solves the fixed point to 1e-10 in log q (bracketed Newton,
    continued from the neighbouring frequency), so it is an exact describing-function
    solution, not a grid value; dashpot convention as `harmonic_balance(viscous="dashpot")`.
    """
    f, A = _checked(model, f_hz, base_g, direction)
    shape, out_shape = batch_shape(model, f.shape)
    P = shape[0]
    w = 2 * np.pi * f
    m = batch_field(model.m, shape)
    mu, gamma = _structure_terms(model, w, shape)
    rigid = gamma is None  # gamma = 1, mu real: skip the complex work
    s, jump, kre, kim = sweep_amplitudes(f, A, direction, shape, joint_terms(model, shape), m, mu, gamma)
    mu_re = np.ascontiguousarray(mu.real)
    q = np.exp(s)
    gain = batch_field(model.sensor_gain, shape)
    tau = batch_field(model.sensor_delay_s, shape)
    if rigid:
        Z = np.empty((P, f.size), complex)
        T = np.empty((P, f.size), complex)
        _k.rigid_output(kre, kim, mu_re, np.ascontiguousarray(m[:, None] * A * np.ones((1, f.size))), w, A,
                        gain, tau, Z, T)
    elif model.fixture is None:  # the shaker's loop (N2): the channel reads 1 + gamma (rel + N' / kappa)
        Z = -gamma * m[:, None] * A / (kre + 1j * kim - mu)  # here gamma is g = gamma / kappa (`_structure_terms`)
        nb = model.neighbour.batched(lambda v: batch_field(v, shape)[:, None])
        k = nb.kappa
        T = gain[:, None] * (1.0 + gamma * k * (-w**2 * Z / A + nb.frf(f) / k)) * np.exp(-1j * w * tau[:, None])
    else:
        Kz = kre + 1j * kim
        Z = -gamma * m[:, None] * A / (Kz - mu)
        # absolute slug acceleration: a_b - omega^2 (W + Z); the can's motion W from its row
        fx = model.fixture
        m_can = batch_field(fx.m_can, shape)[:, None]
        k_can, c_can = can_spring(m_can, batch_field(fx.f_can, shape)[:, None],
                                  batch_field(fx.zeta_can, shape)[:, None])
        a11 = k_can + 1j * w * c_can - w**2 * (m_can + m[:, None])
        W = (-(m_can + m[:, None]) * A + w**2 * m[:, None] * Z) / a11  # can row: a11 W - omega^2 m Z = -(m_can+m) A
        T = gain[:, None] * (1.0 - w**2 * (W + Z) / A) * np.exp(-1j * w * tau[:, None])
    nb = model.neighbour
    if nb is not None and not nb.looped:  # a neighbouring linear mode the response channel also reads (`structure.Neighbour`)
        T = T + gain[:, None] * np.exp(-1j * w * tau[:, None]) * Neighbour(
            batch_field(nb.f_hz, shape)[:, None], batch_field(nb.ratio, shape)[:, None], batch_field(nb.zeta, shape)[:, None]).frf(f)
    return SteadyState(T.reshape(out_shape), Z.reshape(out_shape), q.reshape(out_shape), jump.reshape(out_shape))

