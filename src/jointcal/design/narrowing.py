"""How much a candidate test would narrow each quantity's posterior: the design's criterion.

Criterion (named in every output): the predicted narrowing of the 90% intervals, from a
local Laplace approximation at each posterior draw taken as the truth, and the expected
information gain (EIG) that goes with it:

* Draw j (one of ``design.draws`` posterior draws) plays the truth. The data in hand give
  the Fisher information F_j (`jointcal.posterior.identified.fisher`, unit cube); the
  candidate's read-out at that truth (`jointcal.design.predict.readout`: one more run's q,
  f and zeta, with the draw's noise scales, i.e. the repeat scatter or more) adds
  N_j. With the prior's 12 I, the precision before is A_j = F_j + 12 I and after A_j + N_j.
  A sweep that does not pass quadrature adds nothing.
* For a quantity g with gradient d_j, its spread is s = sqrt(d^T A^-1 d) before and after.
  A quantity the data already identify narrows by s_before / s_after. One they leave to
  the bounds has a current 90% width W set by the bounds, not by s_before: its local width
  is Z90 s capped at W, and it narrows by min(W, Z90 s_before) / min(W, Z90 s_after).
  Either is a ratio "now over after" (at least 1), in the sampling space (log10 for
  log-scaled quantities).
* g is identified after the test at truth j when, with N_j added, less than half of g's
  variance comes from directions the data leave free (`jointcal.posterior.identified.free_share`);
  the test identifies it there when it was not identified before.
* EIG_j = 1/2 log det(I + A_j^-1 N_j) (nats; Laplace approximation).

Over the draws: the expected narrowing is the geometric mean of the ratios; the share of
draws the test identifies g at; the narrowing conditional on either outcome (identified or
not), since the new run itself shows which one happened (in microslip its frequency and
damping follow the power law of the runs in hand; past macroslip they do not); and the
narrowing as a function of how far past the macroslip onset the test goes (`DEPTHS`: the
amplitude reached over phi_max, eq. 3.7), which the test reveals too: past macroslip the
recalibrated posterior identifies phi_max. The further past it, the larger the narrowing,
so a prediction for that depth is the one to hold the outcome against.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..calibrate.space import ParamSpace
from ..posterior.fisher import PRIOR_PRECISION, Z90, fisher, free_share

__all__ = ["CRITERION", "DEPTHS", "depth_labels", "narrowing"]

DEPTHS = (0.0, 1.0, 1.2, 1.5, 2.0, 3.0, np.inf)  # bins of q reached / phi_max


def depth_labels() -> list[str]:
    """Labels of the `DEPTHS` bins, e.g. '<1', '1.2-1.5', '>3'."""
    out = []
    for lo, hi in zip(DEPTHS[:-1], DEPTHS[1:]):
        out.append(f"<{hi:g}" if lo == 0 else f">{lo:g}" if not np.isfinite(hi) else f"{lo:g}-{hi:g}")
    return out

CRITERION = ("predicted narrowing of the 90% intervals (now over after) and expected information gain, from a "
             "local Laplace approximation at each posterior draw taken as the truth: the Fisher information of the "
             "runs in hand plus that of the candidate's phase-resonance read-out (frequency and damping at the "
             "amplitude it reaches, with the draw's noise scales, at least the measured repeat scatter)")


def _spread(grad: NDArray[np.float64], A: NDArray[np.float64]) -> NDArray[np.float64]:
    """sqrt(d^T A^-1 d) for grad (P, n, d) and A (P, d, d) -> (P, n)."""
    sol = np.linalg.solve(A[:, None], grad[..., None])[..., 0]
    return np.sqrt(np.maximum(np.einsum("pnd,pnd->pn", grad, sol), 0.0))


def narrowing(theta: NDArray[np.float64], sigma: NDArray[np.float64], info: NDArray[np.float64],
              read: pd.DataFrame, grads: NDArray[np.float64], names: Sequence[str], width_now: Sequence[float],
              identified: Sequence[bool], cov: NDArray[np.float64], space: ParamSpace, *, m: float,
              targets: Sequence[str] = (), model: str = "harmonic_balance",
              viscous: str = "dashpot") -> tuple[pd.DataFrame, dict[str, float]]:
    """Predicted narrowing of each quantity by one candidate test.

    Parameters
    ----------
    theta, sigma : ndarray, shape (P, 6), (P, 2)
        The draws taken as truths and their noise scales.
    info : ndarray, shape (P, 6, 6)
        Fisher information of the runs in hand at each draw (unit cube).
    read : DataFrame
        The candidate's read-out at each draw (`jointcal.design.predict.readout`).
    grads : ndarray, shape (P, n, 6)
        Gradients of the n quantities (log10 for log-scaled ones) at each draw, unit cube.
    names : sequence of str, length n
    width_now : sequence of float, length n
        Current posterior 90% widths, in the quantities' sampling space.
    identified : sequence of bool, length n
        Whether the data in hand identify each quantity.
    cov : ndarray, shape (6, 6)
        Posterior covariance of the draws in the unit cube.
    space : ParamSpace
    m : float
        Mass, lbf s^2/in.
    targets : sequence of str
        Quantities the test is meant to identify together (e.g. Fs and KT/k).
    model, viscous : str
        As the calibration.

    Returns
    -------
    table : DataFrame
        One row per quantity: quantity, width_now, ratio (geometric mean over the draws),
        width_after (width_now / ratio), share_identified (share of draws at which it is
        identified after the test), ratio_if_identified, ratio_if_not (geometric means over
        the draws at which the test identifies it and the others; NaN if none), and per depth
        bin b of `depth_labels` (q reached over phi_max; draws without a read-out count as
        below 1) share_depth_<b> and ratio_depth_<b> (geometric mean; NaN for an empty bin).
    summary : dict
        eig_nats (mean EIG), reached (share of draws whose sweep passes quadrature),
        share_targets (share of draws at which every target is identified after the test).
    """
    P, d = theta.shape
    ok = read["reached"].to_numpy(bool)
    new = np.zeros_like(info)
    if ok.any():
        new[ok] = fisher(theta[ok], sigma[ok], read["q_in"].to_numpy()[ok, None], read["f_hz"].to_numpy()[ok, None],
                         read["zeta"].to_numpy()[ok, None], space, m=m, model=model, viscous=viscous)
    A0 = info + PRIOR_PRECISION * np.eye(d)
    A1 = A0 + new
    s0, s1 = _spread(grads, A0), _spread(grads, A1)
    w = np.asarray(width_now, dtype=float)[None, :]
    ident = np.asarray(identified, dtype=bool)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(ident, s0 / s1, np.minimum(w, Z90 * s0) / np.minimum(w, Z90 * s1))
    r = np.where(np.isfinite(r) & (r > 0), np.maximum(r, 1.0), 1.0)
    lr = np.log(r)
    with np.errstate(invalid="ignore", divide="ignore"):
        depth = np.where(ok, read["q_in"].to_numpy(float) / space.phi_max(theta), 0.0)
    bins = np.digitize(depth, DEPTHS[1:-1])
    labels = depth_labels()
    rows = []
    all_hit = np.ones(P, bool)
    for i, name in enumerate(names):
        after = free_share(grads[:, i], A1 - PRIOR_PRECISION * np.eye(d), cov) < 0.5
        hit = after & ~(free_share(grads[:, i], info, cov) < 0.5)  # identified by this test, not before it
        if name in targets:
            all_hit &= after
        gm = float(np.exp(np.mean(lr[:, i])))
        rows.append(dict(quantity=name, width_now=float(w[0, i]), ratio=gm, width_after=float(w[0, i]) / gm,
                         share_identified=float(np.mean(after)),
                         ratio_if_identified=float(np.exp(np.mean(lr[hit, i]))) if hit.any() else np.nan,
                         ratio_if_not=float(np.exp(np.mean(lr[~hit, i]))) if (~hit).any() else np.nan,
                         **{f"share_depth_{b}": float(np.mean(bins == k)) for k, b in enumerate(labels)},
                         **{f"ratio_depth_{b}": float(np.exp(np.mean(lr[bins == k, i]))) if (bins == k).any()
                            else np.nan for k, b in enumerate(labels)}))
    ld0, ld1 = np.linalg.slogdet(A0)[1], np.linalg.slogdet(A1)[1]
    return pd.DataFrame(rows), {"eig_nats": float(np.mean(0.5 * (ld1 - ld0))), "reached": float(np.mean(ok)),
                                "share_targets": float(np.mean(all_hit)) if targets else float("nan")}
