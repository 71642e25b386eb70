"""Amplitude-dependent frequency and damping of the Ministack mode.

The mode is the slug (mass m) on a linear spring k in parallel with the Iwan joint,
with a viscous term zeta_v. Two cheap models, both vectorised by broadcasting over
parameter sets and amplitudes (the GA's inner loop):

* `qsma` — quasi-static modal analysis (the paper, section 3.2.2): secant stiffness
  of the backbone for the frequency, Masing dissipation for the damping.
* `harmonic_balance` — first-harmonic balance (describing function): the in-phase
  stiffness of the hysteresis loop for the frequency. This is the frequency a steady
  sweep shows at phase quadrature; QSMA's secant sits above it (0.15% at 1 g, 0.35%
  at 10 g for the paper's Table 3.2 joint).

Damping is the energy-balance equivalent viscous ratio, zeta = D / (2 pi k_eff q**2),
the quantity phase-resonance testing measures. Viscous convention: ``"dashpot"`` is a
dashpot c = 2 zeta_v sqrt((k + KT) m) (zeta_v is its ratio at the stuck-joint
frequency omega_0), adding zeta_v omega_0 / omega -- what a time simulation with that
dashpot shows; ``"constant"`` adds zeta_v as the paper does (eq. 3.9).
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..units import G
from . import _amplitude_kernel
from .iwan import derived, dissipation

__all__ = ["jenkins_inphase", "qsma", "harmonic_balance", "population_curves", "resonance_amplitude", "G"]

Viscous = Literal["dashpot", "constant"]

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(16)
_NODES = 0.5 * (_NODES + 1.0)
_WEIGHTS = 0.5 * _WEIGHTS


def jenkins_inphase(s: ArrayLike) -> NDArray[np.float64]:
    """In-phase first-harmonic stiffness of a unit Jenkins element, g(s).

    s = phi / q is the slip displacement over the motion amplitude; g = 1 when the
    element sticks (s >= 1), else (theta - sin(2 theta)/2) / pi with
    cos(theta) = 1 - 2 s.
    """
    s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    theta = np.arccos(1.0 - 2.0 * s)
    return (theta - 0.5 * np.sin(2.0 * theta)) / np.pi


def _J(chi: NDArray, smax: NDArray) -> NDArray:
    """J = int_0^smax (1 - g(s)) s**chi ds, split at s = 1/2 so both halves are smooth.

    [0, 1/2]: Gauss-Legendre in t = s**(chi+1), which absorbs the s**chi singularity;
    [1/2, smax]: in theta with s = (1 - cos theta)/2, where 1 - g = 1 - (theta -
    sin 2 theta / 2)/pi is smooth (in s it behaves as (1 - s)**1.5 at s = 1).
    16 nodes each: 5e-8 relative error at worst over chi in [-0.95, 0], smax in (0, 1].
    """
    a = chi + 1.0
    t_a = np.minimum(smax, 0.5) ** a
    s = (t_a[..., None] * _NODES) ** (1.0 / a[..., None])
    low = t_a / a * np.sum(_WEIGHTS * (1.0 - jenkins_inphase(s)), axis=-1)
    th0 = 0.5 * np.pi
    th1 = np.arccos(1.0 - 2.0 * np.maximum(smax, 0.5))
    th = th0 + (th1 - th0)[..., None] * _NODES
    s_b = 0.5 * (1.0 - np.cos(th))
    one_minus_g = 1.0 - (th - 0.5 * np.sin(2.0 * th)) / np.pi
    high = (th1 - th0) * np.sum(_WEIGHTS * one_minus_g * s_b ** chi[..., None] * 0.5 * np.sin(th), axis=-1)
    return low + high


def _J_broadcast(chi: NDArray, smax: NDArray) -> NDArray:
    """`_J` over broadcast arrays, evaluated once per distinct chi where smax = 1 (microslip).

    Below macroslip J depends on chi only; a population of P parameter sets at N
    amplitudes then needs P quadratures, not P*N. Same values as `_J` bit for bit.
    """
    J = np.empty(np.shape(chi))
    micro = smax >= 1.0
    if micro.any():
        values, inverse = np.unique(chi[micro], return_inverse=True)
        J[micro] = _J(values, np.ones_like(values))[inverse]
    if not micro.all():
        J[~micro] = _J(chi[~micro], smax[~micro])
    return J


def _joint(q, Fs, KT, chi, beta):
    q, Fs, KT, chi, beta = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (q, Fs, KT, chi, beta)))
    if np.any(q <= 0):
        raise ValueError("Modal amplitudes q must be positive displacements in inches.")
    phi_max, R, S = derived(Fs, KT, chi, beta)
    return q, Fs, KT, chi, beta, phi_max, R, S


def _viscous(zeta_v, omega, omega0, viscous: Viscous):
    if viscous == "dashpot":
        return zeta_v * omega0 / omega
    if viscous == "constant":
        return zeta_v * np.ones_like(omega)
    raise ValueError(f"viscous must be 'dashpot' or 'constant', got {viscous!r}.")


def qsma(q, Fs, KT, chi, beta, k, m, zeta_v, *, viscous: Viscous = "constant"):
    """Quasi-static modal analysis: secant frequency and Masing damping.

    Parameters
    ----------
    q : array_like
        Modal (relative displacement) amplitude, in.
    Fs, KT, chi, beta : array_like
        Iwan parameters (lbf, lbf/in, -, -).
    k : array_like
        Linear spring in parallel with the joint, lbf/in.
    m : array_like
        Slug mass, lbf s^2/in.
    zeta_v : array_like
        Viscous damping ratio (see the module notes for the convention).

    Returns
    -------
    f : ndarray
        Natural frequency, Hz: sqrt(k_sec/m)/2pi, k_sec = k + F_b(q)/q.
    zeta : ndarray
        Damping ratio, D(q)/(2 pi k_sec q^2) + viscous part.
    All inputs broadcast; e.g. parameters of shape (P, 1) and q of shape (N,).
    """
    return _curves(q, Fs, KT, chi, beta, k, m, zeta_v, harmonic=False, viscous=viscous)


def harmonic_balance(q, Fs, KT, chi, beta, k, m, zeta_v, *, viscous: Viscous = "dashpot"):
    """First-harmonic balance (describing function) frequency and damping.

    k_df(q) = k + KT - R q^(chi+1) J(min(1, phi_max/q)) - S (1 - g(phi_max/q)),
    the last term only past macroslip (q > phi_max); omega = sqrt(k_df/m);
    zeta = D(q) / (2 pi k_df q^2) + viscous part. Arguments and returns as `qsma`.
    """
    return _curves(q, Fs, KT, chi, beta, k, m, zeta_v, harmonic=True, viscous=viscous)


def population_curves(theta: ArrayLike, q: ArrayLike, m: float, *, harmonic: bool = True,
                      viscous: Viscous = "dashpot") -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """`harmonic_balance` (or `qsma`) of many parameter sets at the same amplitudes, for a population.

    Parameters
    ----------
    theta : array_like, shape (P, 6)
        Fs (lbf), KT (lbf/in), chi, beta, k (lbf/in), zeta_v per parameter set.
    q : array_like, shape (N,)
        Modal amplitudes, in (> 0).
    m : float
        Slug mass, lbf s^2/in.
    harmonic : bool
        True: `harmonic_balance`; False: `qsma`.
    viscous : {'dashpot', 'constant'}
        Viscous convention (see the module notes).

    Returns
    -------
    f, zeta : ndarray, shape (P, N)
        Frequency, Hz, and damping ratio; the same values as
        ``harmonic_balance(q, *theta[:, :5].T[..., None], m, theta[:, 5:])`` (one call of the kernel,
        without the broadcasting).
    """
    theta = np.asarray(theta, dtype=float)
    rows = np.empty((theta.shape[0], 7))  # the kernel's columns: the six, then m
    rows[:, :6] = theta
    rows[:, 6] = m
    return _run(np.asarray(q, dtype=float).reshape(1, -1), rows, harmonic, viscous)


def _run(q2: NDArray[np.float64], rows: NDArray[np.float64], harmonic: bool, viscous: Viscous):
    """The kernel on amplitudes q2 (P or 1, N) and parameter rows (P, 7); returns f, zeta (P, N)."""
    if viscous not in ("dashpot", "constant"):
        raise ValueError(f"viscous must be 'dashpot' or 'constant', got {viscous!r}.")
    if np.any(q2 <= 0) and rows.shape[0]:
        raise ValueError("Modal amplitudes q must be positive displacements in inches.")
    q2 = np.require(q2, dtype=float, requirements=("C", "W"))  # one signature: C-contiguous, writeable
    f, zeta = np.empty((rows.shape[0], q2.shape[1])), np.empty((rows.shape[0], q2.shape[1]))
    _amplitude_kernel.curves(q2, rows, harmonic, viscous == "dashpot", _NODES, _WEIGHTS, f, zeta)
    return f, zeta


def _curves(q, Fs, KT, chi, beta, k, m, zeta_v, *, harmonic: bool, viscous: Viscous):
    """`harmonic_balance` (harmonic=True) or `qsma` by the numba kernel (`_amplitude_kernel.curves`).

    The kernel takes parameter sets as rows (P, 7) and amplitudes as columns (P or 1, N): parameters
    constant along the last axis (a population (P, 1), or scalars) keep that layout, any other
    broadcast becomes one row per point.
    """
    q = np.asarray(q, dtype=float)
    params = [np.asarray(a, dtype=float) for a in (Fs, KT, chi, beta, k, zeta_v, m)]  # the kernel's columns
    if q.ndim == 0 and all(p.ndim == 0 for p in params):  # one point (the rig truths' bisections): one row
        f, zeta = _run(q.reshape(1, 1), np.array([params]), harmonic, viscous)
        return f[0, 0], zeta[0, 0]
    shape = np.broadcast_shapes(q.shape, *(p.shape for p in params))
    full = shape or (1,)
    if all(p.ndim == 0 or p.shape[-1] == 1 for p in params):  # one parameter set per row
        lead, n = full[:-1], full[-1]
        count = int(np.prod(lead, dtype=int))
        rows = np.empty((count, 7))
        for j, p in enumerate(params):
            rows[:, j] = np.broadcast_to(p, (*lead, 1)).reshape(count)
        one = q.ndim <= 1 or all(d == 1 for d in q.shape[:-1])
        q2 = np.broadcast_to(q.reshape(-1) if one else q, (n,) if one else full).reshape(1 if one else count, n)
    else:  # one parameter set per point
        count = int(np.prod(full, dtype=int))
        rows = np.empty((count, 7))
        for j, p in enumerate(params):
            rows[:, j] = np.broadcast_to(p, full).reshape(count)
        q2 = np.broadcast_to(q, full).reshape(count, 1)
    f, zeta = _run(q2, rows, harmonic, viscous)
    return f.reshape(shape)[()], zeta.reshape(shape)[()]  # [()]: a numpy scalar for scalar inputs, as numpy


# The whole-array numpy expressions the kernel follows, kept as its reference
# (tests/models/test_amplitude_kernel.py, tests/benchmarks/bench_posterior_step.py).

def _qsma_numpy(q, Fs, KT, chi, beta, k, m, zeta_v, *, viscous: Viscous = "constant"):
    """`qsma` in numpy (same arguments and returns)."""
    q, Fs, KT, chi, beta, phi_max, R, S = _joint(q, Fs, KT, chi, beta)
    u = np.minimum(q, phi_max)
    Fb = np.where(q >= phi_max, Fs, KT * u - R * u ** (chi + 2.0) / ((chi + 1.0) * (chi + 2.0)))
    k_sec = k + Fb / q
    omega = np.sqrt(k_sec / m)
    omega0 = np.sqrt((k + KT) / m)
    D = dissipation(q, Fs, KT, chi, beta)
    zeta = D / (2.0 * np.pi * k_sec * q**2) + _viscous(zeta_v, omega, omega0, viscous)
    return omega / (2.0 * np.pi), zeta


def _harmonic_balance_numpy(q, Fs, KT, chi, beta, k, m, zeta_v, *, viscous: Viscous = "dashpot"):
    """`harmonic_balance` in numpy (same arguments and returns)."""
    q, Fs, KT, chi, beta, phi_max, R, S = _joint(q, Fs, KT, chi, beta)
    smax = np.minimum(1.0, phi_max / q)
    k_df = k + KT - R * q ** (chi + 1.0) * _J_broadcast(chi, smax)
    k_df = k_df - np.where(q > phi_max, S * (1.0 - jenkins_inphase(phi_max / q)), 0.0)
    omega = np.sqrt(k_df / m)
    omega0 = np.sqrt((k + KT) / m)
    D = dissipation(q, Fs, KT, chi, beta)
    zeta = D / (2.0 * np.pi * k_df * q**2) + _viscous(zeta_v, omega, omega0, viscous)
    return omega / (2.0 * np.pi), zeta


def resonance_amplitude(level_g, Fs, KT, chi, beta, k, m, zeta_v, *, viscous: Viscous = "dashpot",
                        iterations: int = 80):
    """Steady-state relative amplitude q (in) at phase resonance under base excitation.

    Energy balance at quadrature: the base's effective force m*a (a = level_g * G)
    does work pi m a q per cycle, equal to the dissipation, so
    m a = 2 m omega(q)^2 zeta(q) q (harmonic balance). Solved by bisection in log q.

    Returns
    -------
    q, f, zeta : ndarray
        Amplitude (in), frequency (Hz) and damping ratio at that level.
    """
    a = np.asarray(level_g, dtype=float) * G
    args = np.broadcast_arrays(a, *(np.asarray(x, dtype=float) for x in (Fs, KT, chi, beta, k, m, zeta_v)))
    a, Fs, KT, chi, beta, k, m, zeta_v = args
    phi_max, _, _ = derived(Fs, KT, chi, beta)
    lo = np.log(1e-9 * phi_max)
    hi = np.log(1e4 * phi_max)
    lo, hi = np.broadcast_arrays(lo, hi)
    lo, hi = lo.copy(), hi.copy()
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        q = np.exp(mid)
        f, z = harmonic_balance(q, Fs, KT, chi, beta, k, m, zeta_v, viscous=viscous)
        excess = 2.0 * (2.0 * np.pi * f) ** 2 * z * q - a  # per unit mass
        hi = np.where(excess > 0, mid, hi)
        lo = np.where(excess > 0, lo, mid)
    q = np.exp(0.5 * (lo + hi))
    f, z = harmonic_balance(q, Fs, KT, chi, beta, k, m, zeta_v, viscous=viscous)
    return q, f, z
