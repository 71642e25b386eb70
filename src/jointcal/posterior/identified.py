"""What the data identify: the joint's parameters and combinations, each called identified or not.

Posterior draws alone do not tell a quantity the data fix from one the bounds fix: in
microslip the measured frequencies and damping ratios depend on the joint only through a
few combinations, and the marginal interval of, e.g., Fs or KT is narrowed by the bounds of
k (through K0 = k + KT) rather than by a measurement. So each candidate quantity (the six
parameters, combinations such as K0, eq. 3.5's R and the dissipation law, and the model's
frequency and damping over the measured amplitudes; `quantities`) is judged by where its
posterior spread comes from, with a local Laplace approximation at each posterior draw:

* G_i is the Jacobian of the residuals the likelihood weighs (each run's relative frequency
  and damping residual over the draw's noise scales sigma_f, sigma_zeta) with respect to
  the unit-cube coordinates u of the search space (log10 of the log-scaled parameters, chi
  linear; `jointcal.calibrate.ParamSpace`), by forward differences; F_i = G_i^T G_i is the
  data's Fisher information there (`fisher`). The uniform prior has variance 1/12 along
  every direction of the cube; its Gaussian stand-in adds 12 I.
* The eigenvectors of F_i are the directions the data fix (they narrow the prior's spread
  along them below ``ratio``) and those they leave free (`fixed_directions` counts the
  first). In microslip two directions are free at every draw.
* A quantity's gradient splits into a fixed and a free part; its variance along the fixed
  directions is what the data leave there, along the free ones how far the posterior
  reaches along them. It is identified when, at the median draw, less than half of its
  variance comes from the free directions (`free_share`); its 90% interval is then the
  5-95% quantiles over the draws. No quantity is declared identified in advance: K0
  comes out identified because it does not change along the directions the data leave
  free, Fs and KT because they do.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..calibrate.objective import predict
from ..calibrate.space import PARAMS, ParamSpace
from ..models import derived, dissipation

__all__ = ["Quantity", "quantities", "unit_jacobian", "fisher", "free_share", "fixed_directions",
           "identified_table", "identified_at", "PRIOR_PRECISION"]

PRIOR_PRECISION = 12.0  # 1 / variance of a uniform distribution on [0, 1]
Z90 = 3.2897  # width of a normal 90% interval in standard deviations


@dataclass(frozen=True)
class Quantity:
    """A function of the joint parameters reported with its interval.

    name, unit : labels; kind : 'parameter', 'combination' or 'curve'; log : judged and
    reported in log10 (a positive scale quantity); q_in : amplitude of a curve point (in),
    NaN otherwise; fn : theta (P, 6) physical -> (P,) values.
    """

    name: str
    unit: str
    kind: str
    log: bool
    fn: Callable[[NDArray[np.float64]], NDArray[np.float64]]
    q_in: float = float("nan")


def quantities(q: ArrayLike, *, m: float, model: str = "harmonic_balance", viscous: str = "dashpot",
               space: ParamSpace | None = None) -> list[Quantity]:
    """The candidate quantities: the six parameters, the combinations and the curves over the measured range.

    Parameters
    ----------
    q : array_like, shape (N,)
        Measured amplitudes, in: the curves are reported at their smallest, geometric-mean
        (q_ref) and largest value, and the dissipation at q_ref.
    m : float
        Mass of the model, lbf s^2/in.
    model, viscous : str
        As the calibration (`jointcal.calibrate.predict`).
    space : ParamSpace, optional
        For the parameters' log scaling (default the paper's six).
    """
    q = np.asarray(q, dtype=float)
    q_ref = float(np.exp(np.mean(np.log(q))))
    log = dict(zip(PARAMS, space.log)) if space is not None else {p: p != "chi" for p in PARAMS}
    units = {"Fs": "lbf", "KT": "lbf/in", "chi": "-", "beta": "-", "k": "lbf/in", "zeta_v": "-"}
    out = [Quantity(p, units[p], "parameter", bool(log[p]), lambda t, i=i: t[:, i]) for i, p in enumerate(PARAMS)]
    out += [
        Quantity("K0", "lbf/in", "combination", True, lambda t: t[:, 1] + t[:, 4]),  # stuck stiffness k + KT
        Quantity("R", "lbf/in^(chi+2)", "combination", True, lambda t: derived(*t[:, :4].T)[1]),  # eq. 3.5
        Quantity("D_ref", "lbf in", "combination", True,  # dissipation per cycle at q_ref (eqs. 3.3-3.5)
                 lambda t: dissipation(q_ref, *t[:, :4].T), q_ref),
        Quantity("dissipation_exponent", "-", "combination", False, lambda t: t[:, 2] + 3.0),  # D ~ q^(chi+3)
        Quantity("KT/k", "-", "combination", True, lambda t: t[:, 1] / t[:, 4]),
        Quantity("phi_max", "in", "combination", True, lambda t: derived(*t[:, :4].T)[0]),  # eq. 3.7
    ]
    for label, qq in (("q_min", float(q.min())), ("q_ref", q_ref), ("q_max", float(q.max()))):
        for j, (name, unit) in enumerate((("f", "Hz"), ("zeta", "-"))):
            def curve(t, qq=qq, j=j):
                with np.errstate(all="ignore"):
                    return predict(t, np.array([qq]), m=m, model=model, viscous=viscous)[j][:, 0]  # type: ignore[arg-type]
            out.append(Quantity(f"{name}({label})", unit, "curve", True, curve, qq))
    return out


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
           h: float = 1e-6) -> NDArray[np.float64]:
    """Fisher information of frequency and damping read-outs in the unit cube, at each draw.

    The residuals are those of the likelihood (`jointcal.posterior.likelihood`): (f_i -
    f~(q_i))/f_i over sigma_f and (zeta_i - zeta~(q_i))/zeta_i over sigma_zeta.

    Parameters
    ----------
    theta : array_like, shape (P, 6)
        Draws of (Fs, KT, chi, beta, k, zeta_v), physical units.
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

    Returns
    -------
    ndarray, shape (P, 6, 6)
    """
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    sigma = np.atleast_2d(np.asarray(sigma, dtype=float))
    P = len(theta)
    q, f, zeta = (np.broadcast_to(np.asarray(a, dtype=float), (P, np.shape(a)[-1])) for a in (q, f, zeta))
    d = theta.shape[1]
    qq = np.repeat(q, d + 1, axis=0)  # each draw's amplitudes for its d + 1 stencil points

    def fn(t):
        with np.errstate(all="ignore"):
            fm, zm = predict(t, qq, m=m, model=model, viscous=viscous)  # type: ignore[arg-type]
        return np.concatenate([fm, zm], axis=1)

    _, jac = unit_jacobian(fn, space.to_unit(theta), space, h=h)
    n = q.shape[1]
    scale = np.concatenate([1.0 / (f * sigma[:, :1]), 1.0 / (zeta * sigma[:, 1:])], axis=1)  # (P, 2N)
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


def identified_table(samples: ArrayLike, names: Sequence[str], space: ParamSpace, q: ArrayLike, f: ArrayLike,
                     zeta: ArrayLike, *, m: float, model: str = "harmonic_balance", viscous: str = "dashpot",
                     ratio: float = 0.5) -> tuple[pd.DataFrame, NDArray[np.float64]]:
    """Every candidate quantity with its 90% interval and whether the data identify it.

    Parameters
    ----------
    samples : array_like, shape (P, 8)
        Posterior draws in physical units (``chain.npz``'s ``samples``).
    names : sequence of str
        Their column names (``sample_names``: Fs, KT, chi, beta, k, zeta_v, sigma_f, sigma_zeta).
    space : ParamSpace
        The calibration's bounds.
    q, f, zeta : array_like, shape (N,)
        The measured read-outs the posterior was sampled on.
    m : float
        Mass, lbf s^2/in.
    model, viscous : str
        As the calibration.
    ratio : float
        Spread ratio below which a direction counts as fixed by the data (the posterior's
        ``constrained_ratio``).

    Returns
    -------
    table : pandas.DataFrame
        quantity, unit, kind, log, q_in, q05, median, q95 (physical), prior_lo, prior_hi
        (parameters), free_share (median over the draws), identified (free_share < 0.5),
        fixed_directions (median count over the draws).
    info : ndarray, shape (P, 6, 6)
        The data's Fisher information at each draw (unit cube), for reuse.
    """
    col = {n: i for i, n in enumerate(names)}
    S = np.asarray(samples, dtype=float)
    theta = S[:, [col[p] for p in PARAMS]]
    sigma = S[:, [col["sigma_f"], col["sigma_zeta"]]]
    info = fisher(theta, sigma, q, f, zeta, space, m=m, model=model, viscous=viscous)
    n_fixed = float(np.median(fixed_directions(info, ratio)))
    u = space.to_unit(theta)
    cov = np.cov(u, rowvar=False)
    rows = []
    for qt in quantities(q, m=m, model=model, viscous=viscous, space=space):
        def fn(t, qt=qt):
            with np.errstate(all="ignore"):
                v = qt.fn(t)
                return (np.log10(v) if qt.log else v)[:, None]

        values, jac = unit_jacobian(fn, u, space)
        share = free_share(jac[:, 0, :], info, cov, ratio=ratio)
        ok = np.isfinite(share)
        phys = 10.0 ** values[:, 0] if qt.log else values[:, 0]
        q05, q50, q95 = np.nanpercentile(phys, [5, 50, 95])
        med = float(np.median(share[ok])) if ok.any() else np.nan
        i = PARAMS.index(qt.name) if qt.kind == "parameter" else None
        rows.append(dict(quantity=qt.name, unit=qt.unit, kind=qt.kind, log=qt.log, q_in=qt.q_in, q05=q05,
                         median=q50, q95=q95, prior_lo=space.lo[i] if i is not None else np.nan,
                         prior_hi=space.hi[i] if i is not None else np.nan, free_share=med,
                         identified=bool(med < 0.5), fixed_directions=n_fixed))
    return pd.DataFrame(rows), info


def identified_at(theta: ArrayLike, sigma: ArrayLike, q: ArrayLike, space: ParamSpace, *, m: float,
                  model: str = "harmonic_balance", viscous: str = "dashpot",
                  ratio: float = 0.5) -> dict[str, bool]:
    """Which parameters read-outs at amplitudes `q` would identify at one parameter point.

    For a model known only by a point and per-parameter intervals (the discrepancy stage's
    recalibration): the read-outs are the model's own frequency and damping at `q` with
    relative noise `sigma` (e.g. the measured repeat scatter), and the free directions'
    extent is the prior's (covariance I / 12 in the unit cube) for want of draws.

    Parameters
    ----------
    theta : array_like, shape (6,)
        (Fs, KT, chi, beta, k, zeta_v), physical units.
    sigma : array_like, shape (2,)
        Relative noise of frequency and damping.
    q : array_like, shape (N,)
        Amplitudes of the read-outs, in.
    space : ParamSpace
    m : float
        Mass, lbf s^2/in.
    model, viscous : str
    ratio : float
        As `identified_table`.

    Returns
    -------
    dict
        parameter -> identified.
    """
    th = np.atleast_2d(np.asarray(theta, dtype=float))
    q = np.asarray(q, dtype=float)
    with np.errstate(all="ignore"):
        f, z = predict(th, q, m=m, model=model, viscous=viscous)  # type: ignore[arg-type]
    info = fisher(th, np.atleast_2d(sigma), q, f[0], z[0], space, m=m, model=model, viscous=viscous)
    cov = np.eye(th.shape[1]) / PRIOR_PRECISION
    out = {}
    for i, p in enumerate(PARAMS):
        share = free_share(np.eye(th.shape[1])[i][None], info, cov, ratio=ratio)
        out[p] = bool(share[0] < 0.5)
    return out
