"""Every candidate test predicted: read-out spread, sweep-rate check and narrowing of each quantity.

`evaluate` takes ``draws`` posterior draws as truths (seeded choice), the Fisher
information of the runs in hand at each (`jointcal.posterior.identified.fisher`), and for
every candidate level and direction the predicted read-out
(`jointcal.design.predict.readout`) and narrowing (`jointcal.design.narrowing`). The
sweep rate does not change the steady-state read-out; it changes the test's duration and
the sweep-rate parameter eta = rate / (f zeta)^2: a draw's read-out counts only where eta
stays below ``modal.eta_max`` (a quasi-steady read-out; a joint that slips through at a
high level loses its damping and fails it at any rate).
The predictive spread of the read-out frequency (its 90% range over the draws) is given
against the measured repeat scatter of the frequency: a test whose spread is within the
scatter cannot tell the draws apart.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..calibrate.space import PARAMS, ParamSpace
from ..posterior.fisher import fisher, unit_jacobian
from ..posterior.identified import quantities
from .narrowing import narrowing
from .predict import readout
from .settings import DesignSettings

__all__ = ["REPORTED", "evaluate"]

REPORTED = (*PARAMS, "K0", "KT/k")  # quantities whose narrowing is predicted


def _width(row: pd.Series) -> float:
    """90% width in the sampling space: decades for a log-scaled quantity."""
    return float(np.log10(row["q95"] / row["q05"]) if row["log"] else row["q95"] - row["q05"])


def evaluate(cands: pd.DataFrame, samples: NDArray[np.float64], names: Sequence[str], space: ParamSpace,
             identified: pd.DataFrame, q: NDArray[np.float64], f: NDArray[np.float64], zeta: NDArray[np.float64],
             settings: DesignSettings, *, m: float, rel_scatter_f: float, eta_max: float, targets: Sequence[str],
             model: str = "harmonic_balance", viscous: str = "dashpot") -> tuple[pd.DataFrame, pd.DataFrame]:
    """Predict every candidate of one assembly.

    Parameters
    ----------
    cands : DataFrame
        `jointcal.design.candidates.candidates`.
    samples, names : posterior draws (physical units) and their column names (``chain.npz``).
    space : ParamSpace
        The calibration's bounds.
    identified : DataFrame
        `jointcal.posterior.identified.identified_table` of these draws.
    q, f, zeta : ndarray, shape (N,)
        The runs in hand (in, Hz, -).
    settings : DesignSettings
    m : float
        Slug mass, lbf s^2/in.
    rel_scatter_f : float
        Measured relative repeat scatter of the frequency (pooled).
    eta_max : float
        Largest sweep-rate parameter of a quasi-steady read-out (``modal.eta_max``).
    targets : sequence of str
        Quantities the next test is meant to identify (e.g. Fs and KT/k).
    model, viscous : str
        As the calibration.

    Returns
    -------
    table : DataFrame
        One row per candidate (the columns of `cands`, then the read-out quantiles f_q05,
        f_q50, f_q95 (Hz), zeta_q05/q50/q95, q_q50 (in), peak_g_q50, peak_g_q95 (g), reached
        (share of draws whose sweep passes quadrature), macroslip (share past phi_max),
        spread_f_over_scatter, eta_q95, valid (share of draws with a quasi-steady read-out at
        this rate), eig_nats, share_targets, per quantity ratio_<name>, ratio_if_identified_<name>,
        ratio_if_not_<name>, share_identified_<name>, per depth bin share_depth_<bin> and, for
        the targets, ratio_depth_<bin>_<name>; `jointcal.design.narrowing`).
    per_quantity : DataFrame
        The narrowing rows of every candidate (level_g, direction, sweep_rate_hz_per_s, quantity, ...).
    """
    col = {n: i for i, n in enumerate(names)}
    rng = np.random.default_rng(settings.seed)
    pick = np.sort(rng.choice(len(samples), min(settings.draws, len(samples)), replace=False))
    theta = samples[pick][:, [col[p] for p in PARAMS]]
    sigma = samples[pick][:, [col["sigma_f"], col["sigma_zeta"]]]
    info = fisher(theta, sigma, q, f, zeta, space, m=m, model=model, viscous=viscous)
    cov = np.cov(space.to_unit(samples[:, [col[p] for p in PARAMS]]), rowvar=False)
    qs = {qt.name: qt for qt in quantities(q, m=m, model=model, viscous=viscous, space=space)}
    idt = identified.set_index("quantity")
    u = space.to_unit(theta)
    grads = []
    for name in REPORTED:
        qt = qs[name]

        def fn(t, qt=qt):
            with np.errstate(all="ignore"):
                v = qt.fn(t)
                return (np.log10(v) if qt.log else v)[:, None]

        grads.append(unit_jacobian(fn, u, space)[1][:, 0])
    grads = np.stack(grads, axis=1)
    width_now = [_width(idt.loc[n]) for n in REPORTED]
    ident = [bool(idt.loc[n, "identified"]) for n in REPORTED]
    rows, per_q = [], []
    for (level, direction), group in cands.groupby(["level_g", "direction"], sort=False):
        read = readout(theta, float(level), direction, m=m, f_lo_hz=float(group["f_lo_hz"].iloc[0]),
                       f_hi_hz=float(group["f_hi_hz"].iloc[0]), n_frequencies=settings.frequencies, model=model,
                       viscous=viscous)
        ok = read["reached"].to_numpy(bool)
        fz = read[["f_hz", "zeta"]].to_numpy()
        fq = np.percentile(fz[ok, 0], [5, 50, 95]) if ok.any() else np.full(3, np.nan)
        zq = np.percentile(fz[ok, 1], [5, 50, 95]) if ok.any() else np.full(3, np.nan)
        base = dict(f_q05=fq[0], f_q50=fq[1], f_q95=fq[2], zeta_q05=zq[0], zeta_q50=zq[1], zeta_q95=zq[2],
                    q_q50=float(np.nanmedian(read["q_in"])) if ok.any() else np.nan,
                    peak_g_q50=float(np.median(read["peak_g"])), peak_g_q95=float(np.percentile(read["peak_g"], 95)),
                    reached=float(ok.mean()), macroslip=float(read["macroslip"].mean()),
                    spread_f_over_scatter=float((fq[2] - fq[0]) / fq[1] / rel_scatter_f) if ok.any() else np.nan)
        for c in group.itertuples(index=False):
            with np.errstate(all="ignore"):
                eta = c.sweep_rate_hz_per_s / (fz[:, 0] * fz[:, 1]) ** 2
            valid = ok & (eta <= eta_max)  # a read-out the modal stage takes as quasi-steady
            table, summ = narrowing(theta, sigma, info, read.assign(reached=valid), grads, REPORTED, width_now,
                                    ident, cov, space, m=m, targets=targets, model=model, viscous=viscous)
            per_q.append(table.assign(level_g=level, direction=direction, sweep_rate_hz_per_s=c.sweep_rate_hz_per_s))
            row = {**c._asdict(), **base, "eta_q95": float(np.nanpercentile(np.where(ok, eta, np.nan), 95))
                   if ok.any() else np.nan, "valid": float(valid.mean()), "eig_nats": summ["eig_nats"],
                   "share_targets": summ["share_targets"]}
            for _, t in table.iterrows():
                n = t["quantity"]
                row.update({f"ratio_{n}": t["ratio"], f"ratio_if_identified_{n}": t["ratio_if_identified"],
                            f"ratio_if_not_{n}": t["ratio_if_not"], f"share_identified_{n}": t["share_identified"]})
                if n in targets:  # the narrowing by how far past macroslip the test goes
                    row.update({f"{c}_{n}": t[c] for c in t.index if c.startswith("ratio_depth_")})
            row.update({c: table[c].iloc[0] for c in table.columns if c.startswith("share_depth_")})
            rows.append(row)
    return pd.DataFrame(rows), pd.concat(per_q, ignore_index=True)
