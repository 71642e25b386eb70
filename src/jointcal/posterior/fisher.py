"""The local Laplace approximation behind `identified`: the data's Fisher information in the unit cube.

* `unit_jacobian` -- values and forward-difference Jacobian of a function of the physical
  parameters with respect to the unit-cube coordinates of a `ParamSpace`;
* `fisher` -- the Fisher information of frequency and damping read-outs (the likelihood's
  relative residuals over the noise scales) at each posterior draw;
* `free_share` -- the share of a quantity's variance along the directions the data leave free;
* `fixed_directions` -- how many directions the data fix.

The uniform prior on the unit cube has variance 1/12 along every direction; its Gaussian
stand-in adds `PRIOR_PRECISION` I to the information.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..calibrate.objective import predict
from ..calibrate.space import ParamSpace

__all__ = ["PRIOR_PRECISION", "Z90", "unit_jacobian", "fisher", "free_share", "fixed_directions"]

PRIOR_PRECISION = 12.0  # 1 / variance of a uniform distribution on [0, 1]
Z90 = 3.2897  # width of a normal 90% interval in standard deviations


def _steps(u: NDArray[np.float64], h: float) -> NDArray[np.float64]:
    """Forward steps in the unit cube, backward where a forward step would leave it, shape (P, d)."""
    return np.where(u + h <= 1.0, h, -h)


def unit_jacobian(fn: Callable[[NDArray[np.float64]], NDArray[np.float64]], u: NDArray[np.float64],
                  space: ParamSpace, *, h: float = 1e-6) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Values and forward-difference Jacobian of ``fn(theta) -> (P, k)`` in the unit cube.

    Parameters
    ----------
    fn : callable
        Physical parameters (P, d) -> outputs (P, k).
    u : ndarray, shape (P, d)
        Unit-cube points.
    space : ParamSpace
    h : float
        Step in the unit cube.

    Returns
    -------
    values : ndarray, shape (P, k)
    jac : ndarray, shape (P, k, d)
    """
    u = np.atleast_2d(np.asarray(u, dtype=float))
    P, d = u.shape
    step = _steps(u, h)
    pts = np.concatenate([u[:, None, :], u[:, None, :] + np.eye(d)[None] * step[:, :, None]], axis=1)
    y = np.asarray(fn(space.to_physical(pts.reshape(-1, d))), dtype=float).reshape(P, d + 1, -1)
    return y[:, 0], np.moveaxis((y[:, 1:] - y[:, :1]) / step[:, :, None], 1, 2)


def fisher(theta: ArrayLike, sigma: ArrayLike, q: ArrayLike, f: ArrayLike, zeta: ArrayLike, space: ParamSpace, *,
           m: float, model: str = "harmonic_balance", viscous: str = "dashpot",
           h: float = 1e-6, weight: ArrayLike | None = None) -> NDArray[np.float64]:
    """Fisher information of frequency and damping read-outs in the unit cube, at each draw.

    The residuals are those of the likelihood (`jointcal.posterior.likelihood`): (f_i -
    f~(q_i))/f_i over sigma_f and (zeta_i - zeta~(q_i))/zeta_i over sigma_zeta.

    Parameters
    ----------
    theta : array_like, shape (P, n)
        Draws of the space's parameters (Fs, KT, chi, beta, k, zeta_v, any grown), physical units.
    sigma : array_like, shape (P, 2)
        Each draw's relative noise scales of f and zeta.
    q, f, zeta : array_like, shape (N,) or (P, N)
        Amplitudes (in), frequencies (Hz) and damping ratios of the read-outs: the measured
        ones (shared) or hypothetical ones per draw.
    space : ParamSpace
    m : float
        Mass, lbf s^2/in.
    model, viscous : str
        As the calibration.
    h : float
        Finite-difference step in the unit cube.
    weight : array_like, shape (N,), optional
        Each read-out's weight in the likelihood (a ring-down's windows 1/k each); default 1.

    Returns
    -------
    ndarray, shape (P, n, n)
    """
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    sigma = np.atleast_2d(np.asarray(sigma, dtype=float))
    P = len(theta)
    q, f, zeta = (np.broadcast_to(np.asarray(a, dtype=float), (P, np.shape(a)[-1])) for a in (q, f, zeta))
    d = theta.shape[1]
    qq = np.repeat(q, d + 1, axis=0)  # each draw's amplitudes for its d + 1 stencil points

    def fn(t):
        with np.errstate(all="ignore"):
            fm, zm = predict(space.joint(t), qq, m=m, model=model, viscous=viscous)  # type: ignore[arg-type]
        return np.concatenate([fm, zm], axis=1)

    _, jac = unit_jacobian(fn, space.to_unit(theta), space, h=h)
    scale = np.concatenate([1.0 / (f * sigma[:, :1]), 1.0 / (zeta * sigma[:, 1:])], axis=1)  # (P, 2N)
    if weight is not None:
        scale = scale * np.sqrt(np.tile(np.asarray(weight, dtype=float), 2))
    G = np.where(np.isfinite(jac), jac, 0.0) * scale[:, :, None]
    return np.einsum("pki,pkj->pij", G, G)


def free_share(grad: NDArray[np.float64], info: NDArray[np.float64], cov: NDArray[np.float64], *,
               ratio: float = 0.5) -> NDArray[np.float64]:
    """Share of a quantity's posterior variance that comes from directions the data leave free, per draw.

    At each draw the eigenvectors of the data's Fisher information F split the unit cube
    into fixed directions (the data narrow the prior's spread along them below `ratio`:
    sqrt(12 / (12 + mu)) < ratio for eigenvalue mu) and free ones. The gradient d of the
    quantity splits accordingly, d = d_fixed + d_free. Along the fixed directions its spread
    is what the data leave, d_fixed^T (F + 12 I)^-1 d_fixed; along the free ones, how far the
    posterior reaches along them, d_free^T C d_free with C the posterior covariance in the
    cube. Returns d_free^T C d_free / (both), in [0, 1] (NaN for a zero gradient).

    Parameters
    ----------
    grad : ndarray, shape (P, d)
        Gradient of the quantity at each draw, unit cube.
    info : ndarray, shape (P, d, d)
        The data's Fisher information at each draw.
    cov : ndarray, shape (d, d)
        Posterior covariance of the draws in the unit cube.
    ratio : float
        Spread ratio below which a direction counts as fixed by the data.
    """
    mu, V = np.linalg.eigh(info)
    fixed = np.sqrt(PRIOR_PRECISION / (PRIOR_PRECISION + np.maximum(mu, 0.0))) < ratio  # (P, d)
    g = np.where(np.isfinite(grad), grad, 0.0)
    coef = np.einsum("pij,pi->pj", V, g)  # components along the eigenvectors
    d_free = np.einsum("pij,pj->pi", V, np.where(fixed, 0.0, coef))
    d_fix = g - d_free
    A = info + PRIOR_PRECISION * np.eye(g.shape[-1])
    v_fix = np.einsum("pi,pi->p", d_fix, np.linalg.solve(A, d_fix[..., None])[..., 0])
    v_free = np.einsum("pi,ij,pj->p", d_free, cov, d_free)
    total = v_fix + v_free
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, v_free / total, np.nan)


def fixed_directions(info: NDArray[np.float64], ratio: float = 0.5) -> NDArray[np.int_]:
    """Number of directions at each draw along which the data narrow the prior's spread below `ratio`.

    An eigenvalue mu of F shrinks the spread along its eigenvector to sqrt(12 / (12 + mu)) of the
    prior's; counted when that is below `ratio`. Returns shape (P,).
    """
    mu = np.linalg.eigvalsh(info)
    return np.sum(np.sqrt(PRIOR_PRECISION / (PRIOR_PRECISION + np.maximum(mu, 0.0))) < ratio, axis=-1)
