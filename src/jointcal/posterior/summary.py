"""Posterior summaries: quantiles, tau, n_eff, prior-width ratios, plain-language constraints, bands.

All functions take plain arrays in the GA's space x (log10 Fs, log10 KT, chi, log10 beta,
log10 k, log10 zeta_v, any grown parameters, then log10 sigma_f, log10 sigma_zeta: the
columns of a `ParamSpace` followed by the two noise scales) and return tables or text.
"A parameter the data constrain" means: its posterior 90% interval (q05-q95) is narrower
than ``ratio`` (default 0.5) times its prior width, both measured in x (decades for the
log-scaled parameters); a flat posterior has a ratio of 0.9.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..calibrate.objective import predict
from ..calibrate.settings import JOINT
from ..calibrate.space import PARAMS, ParamSpace
from .likelihood import NOISE

__all__ = ["NAMES", "burn_in", "summarize", "draw_quantiles", "constraints_text", "predictive_band"]

NAMES: tuple[str, ...] = (*PARAMS, *NOISE)


def burn_in(tau: NDArray[np.float64], steps: int, factor: float = 5.0) -> int:
    """Steps to discard: ``factor * max(tau)``, at most half the chain."""
    t = np.nanmax(tau) if np.any(np.isfinite(tau)) else steps / 2
    return int(min(np.ceil(factor * t), steps // 2))


def _phys(x: NDArray[np.float64], space: ParamSpace) -> NDArray[np.float64]:
    """x coordinates (..., k) of the space's columns then the noise scales (log10) to physical values."""
    x = np.asarray(x, dtype=float)
    return np.where(np.r_[space.is_log, True, True][: x.shape[-1]], 10.0**x, x)


def summarize(chain_x: NDArray[np.float64], lower: NDArray[np.float64], upper: NDArray[np.float64], *,
              burn: int, ratio: float = 0.5, space: ParamSpace = JOINT) -> pd.DataFrame:
    """Table of the posterior of every parameter (and two derived quantities).

    Parameters
    ----------
    chain_x : ndarray, shape (steps, walkers, n + 2)
        Chain in x coordinates (see module notes).
    lower, upper : ndarray, shape (n + 2,)
        Prior bounds in x.
    burn : int
        Steps discarded at the start.
    ratio : float
        Width ratio below which a parameter counts as constrained.
    space : ParamSpace
        What the first n columns are (names, scaling, units); default the joint's six.

    Returns
    -------
    pandas.DataFrame
        Columns param, unit, median, q05, q95 (physical units), tau (steps), n_eff
        (independent samples after burn-in), prior_lo, prior_hi (physical),
        width_ratio (posterior 90% width / prior width in x), constrained (empty
        for the derived rows). Extra rows: K0 = k + KT (lbf/in) and phi_max (in, eq. 3.7).
    """
    import emcee  # here: it imports scipy.stats (~1 s), which the figure, report and design jobs never need

    kept = chain_x[burn:]
    steps, walkers, _ = kept.shape
    flat = kept.reshape(-1, kept.shape[-1])
    tau = emcee.autocorr.integrated_time(kept, tol=0)
    q05, q50, q95 = np.percentile(flat, [5, 50, 95], axis=0)
    width = (q95 - q05) / (upper - lower)
    units = (*space.units, *("-" for _ in NOISE))
    rows = [dict(param=name, unit=unit, median=float(_phys(q50, space)[i]), q05=float(_phys(q05, space)[i]),
                 q95=float(_phys(q95, space)[i]), tau=float(tau[i]), n_eff=float(steps * walkers / tau[i]),
                 prior_lo=float(_phys(lower, space)[i]), prior_hi=float(_phys(upper, space)[i]),
                 width_ratio=float(width[i]), constrained=bool(width[i] < ratio))
            for i, (name, unit) in enumerate(zip((*space.names, *NOISE), units))]
    p = _phys(kept[..., :space.ndim], space)
    extra = {"K0": (space.stuck_stiffness(p), "lbf/in"), "phi_max": (space.phi_max(p), "in")}
    for name, (series, unit) in extra.items():
        t = float(emcee.autocorr.integrated_time(np.log(series)[..., None], tol=0)[0])
        lo, med, hi = np.percentile(series.ravel(), [5, 50, 95])
        rows.append(dict(param=name, unit=unit, median=float(med), q05=float(lo), q95=float(hi), tau=t,
                         n_eff=float(steps * walkers / t), prior_lo=np.nan, prior_hi=np.nan, width_ratio=np.nan,
                         constrained=None))
    return pd.DataFrame(rows)


def _fmt(v: float) -> str:
    return f"{v:.3g}"


def constraints_text(summary: pd.DataFrame, chain_x: NDArray[np.float64], *, burn: int, q_max: float,
                     ratio: float = 0.5, weak: float = 0.1, n_corr: int = 3, space: ParamSpace = JOINT) -> str:
    """Plain-language sentences: which parameters the data do not constrain, and the strongest correlations.

    Parameters
    ----------
    summary : pandas.DataFrame
        Output of `summarize`.
    chain_x : ndarray, shape (steps, walkers, n + 2)
        The chain in x.
    burn : int
        Steps discarded.
    q_max : float
        Largest measured amplitude, in.
    ratio, weak : float
        Width ratios above which a parameter is called unconstrained / weakly constrained.
    n_corr : int
        Number of correlations reported (those with |r| >= 0.5).
    space : ParamSpace
        What the first n columns are; default the joint's six.
    """
    lines = []
    main = summary[summary["param"].isin(space.names)]
    for _, r in main.iterrows():
        unit = "" if r["unit"] == "-" else f" {r['unit']}"
        rng = f"{_fmt(r['q05'])} to {_fmt(r['q95'])}{unit}"
        share = f"{100 * r['width_ratio']:.0f}%"
        if r["width_ratio"] >= ratio:
            lines.append(f"{r['param']} is not constrained by the data: its 90% interval ({rng}) spans {share} "
                         "of the prior range, so its value reflects the bounds, not the measurements.")
        elif r["width_ratio"] >= weak:
            lines.append(f"{r['param']} is only weakly constrained: its 90% interval ({rng}) still spans {share} "
                         "of the prior range.")
        else:
            lines.append(f"{r['param']} is constrained: 90% interval {rng} ({share} of the prior range).")
    pm = summary.set_index("param").loc["phi_max"]
    if q_max < pm["q05"]:
        lines.append(f"All measured amplitudes (up to {_fmt(q_max)} in) lie below macroslip (phi_max 90% interval "
                     f"{_fmt(pm['q05'])} to {_fmt(pm['q95'])} in): in microslip the frequency and damping depend on "
                     "the joint only through k + KT, R q^(chi+1) (eq. 3.5), chi and zeta_v, so Fs, beta and the "
                     "split of k + KT between k and KT are fixed only by the bounds and the onset of macroslip.")
    n = space.ndim
    flat = chain_x[burn:, :, :n].reshape(-1, n)  # the space's columns, not the noise scales
    corr = np.corrcoef(flat, rowvar=False)
    pairs = sorted(((abs(corr[i, j]), i, j) for i in range(n) for j in range(i + 1, n)), reverse=True)
    strong = [(c, i, j) for c, i, j in pairs if c >= 0.5][:n_corr]
    for c, i, j in strong:
        sign = "rises" if corr[i, j] > 0 else "falls"
        lines.append(f"Strong correlation ({corr[i, j]:+.2f}, in the sampling space): as {space.names[i]} rises, "
                     f"{space.names[j]} {sign}; the data fix a combination of the two better than either.")
    if not strong:
        lines.append("No pair of parameters is strongly correlated (all |r| < 0.5 in the sampling space).")
    return "\n".join(lines) + "\n"


def predictive_band(samples: NDArray[np.float64], q: Sequence[float] | NDArray[np.float64], *, m: float,
                    model: str = "harmonic_balance", viscous: str = "dashpot") -> pd.DataFrame:
    """90% posterior band of the model's f and zeta versus amplitude.

    Parameters
    ----------
    samples : ndarray, shape (S, 6)
        Posterior draws of the joint's parameters (`ParamSpace.joint`), physical units.
    q : array_like, shape (N,)
        Amplitudes, in.
    m : float
        Slug mass, lbf s^2/in.
    model, viscous : str
        As the calibration.

    Returns
    -------
    pandas.DataFrame
        Columns q_in, f_q05, f_q50, f_q95 (Hz), zeta_q05, zeta_q50, zeta_q95. The band is
        that of the model curve (parameter uncertainty); measurement noise is not added.
    """
    q = np.asarray(q, dtype=float)
    f, z = predict(samples, q, m=m, model=model, viscous=viscous)  # type: ignore[arg-type]
    fq = np.percentile(f, [5, 50, 95], axis=0)
    zq = np.percentile(z, [5, 50, 95], axis=0)
    return pd.DataFrame({"q_in": q, "f_q05": fq[0], "f_q50": fq[1], "f_q95": fq[2],
                         "zeta_q05": zq[0], "zeta_q50": zq[1], "zeta_q95": zq[2]})


def draw_quantiles(draws: NDArray[np.float64], names: Sequence[str]) -> pd.DataFrame:
    """The 5%, 50% and 95% quantiles of each column of posterior draws (S, n), indexed by `names`.

    Columns q05, median, q95, in the draws' (physical) units: the 90% interval and the median.
    """
    q05, q50, q95 = np.quantile(np.asarray(draws, dtype=float), [0.05, 0.5, 0.95], axis=0)
    return pd.DataFrame({"q05": q05, "median": q50, "q95": q95}, index=pd.Index(list(names), name="param"))
