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
  data's Fisher information there (`jointcal.posterior.fisher`). The uniform prior has variance 1/12 along
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

import json
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..calibrate.data import read_modal
from ..calibrate.objective import predict
from ..calibrate.settings import JOINT, CalibrateSettings
from ..calibrate.space import ParamSpace
from ..io import write_csv_atomic
from ..models import derived, dissipation
from .fisher import PRIOR_PRECISION, fisher, fixed_directions, free_share, unit_jacobian
from .settings import PosteriorSettings

__all__ = ["Quantity", "quantities", "unit_jacobian", "fisher", "free_share", "fixed_directions",
           "identified_table", "identified_at", "unsettled", "settled", "write_identified", "PRIOR_PRECISION"]



@dataclass(frozen=True)
class Quantity:
    """A function of the joint parameters reported with its interval.

    name, unit : labels; kind : 'parameter', 'combination' or 'curve'; log : judged and
    reported in log10 (a positive scale quantity); q_in : amplitude of a curve point (in),
    NaN otherwise; fn : theta (P, n) physical, columns of the space -> (P,) values.
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
        The parameters (names, units, log scaling; default the paper's six); the
        combinations and curves read the joint's by name.
    """
    q = np.asarray(q, dtype=float)
    q_ref = float(np.exp(np.mean(np.log(q))))
    sp = JOINT if space is None else space

    def iwan(t):
        i = sp.iwan(t)
        return i.Fs, i.KT, i.chi, i.beta

    out = [Quantity(p, unit, "parameter", bool(log), lambda t, p=p: sp.column(t, p))
           for p, unit, log in zip(sp.names, sp.units, sp.log)]
    out += [
        Quantity("K0", "lbf/in", "combination", True, sp.stuck_stiffness),  # stuck stiffness k + KT
        Quantity("R", "lbf/in^(chi+2)", "combination", True, lambda t: derived(*iwan(t))[1]),  # eq. 3.5
        Quantity("D_ref", "lbf in", "combination", True,  # dissipation per cycle at q_ref (eqs. 3.3-3.5)
                 lambda t: dissipation(q_ref, *iwan(t)), q_ref),
        Quantity("dissipation_exponent", "-", "combination", False,
                 lambda t: sp.column(t, "chi") + 3.0),  # D ~ q^(chi+3)
        Quantity("KT/k", "-", "combination", True, lambda t: sp.column(t, "KT") / sp.column(t, "k")),
        Quantity("phi_max", "in", "combination", True, sp.phi_max),  # eq. 3.7
    ]
    for label, qq in (("q_min", float(q.min())), ("q_ref", q_ref), ("q_max", float(q.max()))):
        for j, (name, unit) in enumerate((("f", "Hz"), ("zeta", "-"))):
            def curve(t, qq=qq, j=j):
                with np.errstate(all="ignore"):
                    return predict(sp.joint(t), np.array([qq]), m=m, model=model,  # type: ignore[arg-type]
                                   viscous=viscous)[j][:, 0]
            out.append(Quantity(f"{name}({label})", unit, "curve", True, curve, qq))
    return out


def identified_table(samples: ArrayLike, names: Sequence[str], space: ParamSpace, q: ArrayLike, f: ArrayLike,
                     zeta: ArrayLike, *, m: float, model: str = "harmonic_balance", viscous: str = "dashpot",
                     ratio: float = 0.5, why_not: str = "",
                     weight: ArrayLike | None = None) -> tuple[pd.DataFrame, NDArray[np.float64]]:
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
    why_not : str
        `unsettled`'s sentence for a chain that did not converge or has separated modes,
        kept in the ``why_not`` column of the parameters and combinations: `settled` then
        reports none of them identified (the curves at the measured amplitudes, fixed by the
        read-outs themselves, still are). ``identified`` stays the local information's
        judgement, which the design stage reads to choose what the next test must fix.
    weight : array_like, shape (N,), optional
        The read-outs' weights in the likelihood (`jointcal.calibrate.ModalData.weight`); default 1.

    Returns
    -------
    table : pandas.DataFrame
        quantity, unit, kind, log, q_in, q05, median, q95 (physical), prior_lo, prior_hi
        (parameters), free_share (median over the draws), identified (free_share < 0.5),
        fixed_directions (median count over the draws), why_not.
    info : ndarray, shape (P, 6, 6)
        The data's Fisher information at each draw (unit cube), for reuse.
    """
    col = {n: i for i, n in enumerate(names)}
    S = np.asarray(samples, dtype=float)
    theta = S[:, [col[p] for p in space.names]]
    sigma = S[:, [col["sigma_f"], col["sigma_zeta"]]]
    info = fisher(theta, sigma, q, f, zeta, space, m=m, model=model, viscous=viscous, weight=weight)
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
        i = space.index(qt.name) if qt.kind == "parameter" else None
        rows.append(dict(quantity=qt.name, unit=qt.unit, kind=qt.kind, log=qt.log, q_in=qt.q_in, q05=q05,
                         median=q50, q95=q95, prior_lo=space.lo[i] if i is not None else np.nan,
                         prior_hi=space.hi[i] if i is not None else np.nan, free_share=med,
                         identified=bool(med < 0.5), fixed_directions=n_fixed,
                         why_not=why_not if qt.kind != "curve" else ""))
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
    theta : array_like, shape (n,)
        The space's parameters (Fs, KT, chi, beta, k, zeta_v, any grown), physical units.
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
        f, z = predict(space.joint(th), q, m=m, model=model, viscous=viscous)  # type: ignore[arg-type]
    info = fisher(th, np.atleast_2d(sigma), q, f[0], z[0], space, m=m, model=model, viscous=viscous)
    cov = np.eye(th.shape[1]) / PRIOR_PRECISION
    out = {}
    for p in space.names:
        share = free_share(np.eye(th.shape[1])[space.index(p)][None], info, cov, ratio=ratio)
        out[p] = bool(share[0] < 0.5)
    return out


def unsettled(chain: Mapping[str, Any], names: Sequence[str], *, tau_factor: float = 50.0,
              params: Sequence[str] = ("Fs", "KT", "chi", "beta", "k", "zeta_v")) -> str:
    """Why a chain cannot identify a parameter on its own, with what to run ("" when it can).

    A chain shorter than ``tau_factor`` autocorrelation times has not forgotten where its
    walkers started, and one with separated modes (`jointcal.posterior.modes`) has a median
    between them that describes neither: neither gives a parameter as identified.

    Parameters
    ----------
    chain : mapping
        ``chain.npz``'s arrays: tau_history, converged, stop_reason, projected_steps, samples,
        sample_mode.
    names : sequence of str
        The samples' column names (``sample_names``).
    tau_factor : float
        ``posterior.tau_factor``.
    params : sequence of str
        The parameters located in each mode's words.

    Returns
    -------
    str
        One or two sentences (the cause and the setting or test that settles it), or "".
    """
    why = []
    hist = np.asarray(chain["tau_history"], dtype=float)
    n, tau = float(hist[-1, 0]), float(np.max(hist[-1, 1:]))
    if not bool(chain["converged"]):
        need = float(chain.get("projected_steps", np.nan))
        need = need if np.isfinite(need) and need > n else tau_factor * tau * 1.2
        steps = int(np.ceil(need / 1000.0) * 1000)
        why.append(f"the posterior did not converge ({n / tau:.1f} of the {tau_factor:g} autocorrelation times "
                   f"posterior.tau_factor asks for); run it longer with `posterior: {{max_steps: {steps}, "
                   "stop_projected: 0}` in a config file (the chain resumes from its checkpoint)")
    if "sample_mode" in chain and int(np.max(chain["sample_mode"])) > 0:
        from .modes import find_modes

        modes = find_modes(np.asarray(chain["samples"], dtype=float), list(names), labels=chain["sample_mode"])
        parts = []
        for k, g in modes.groupby("mode"):
            g = g.set_index("param")
            loc = ", ".join(f"{p} {g.loc[p, 'median']:.3g}" for p in params if p in g.index)
            parts.append(f"mode {k + 1} ({100 * g['weight'].iloc[0]:.0f}% of the draws): {loc}")
        why.append(f"the posterior has {int(modes['mode'].max()) + 1} separated modes ({'; '.join(parts)}); "
                   "a test that tells them apart (a level past the macroslip onset of one of them), or "
                   "calibrate.bounds that keep one, settles which holds")
    if not why:
        return ""
    return ("No parameter is identified from this chain alone: " + "; and ".join(why) + ".")


def settled(table: pd.DataFrame) -> pd.DataFrame:
    """``identified.csv`` as a user is told it: a row with a `unsettled` reason (``why_not``) is not identified.

    A table without the column (written before it existed) is returned as it is.
    """
    if "why_not" not in table:
        return table
    why = table["why_not"].fillna("").astype(str)
    return table.assign(identified=table["identified"].astype(bool) & (why == ""), why_not=why)


def write_identified(modal_csv: str | os.PathLike[str], ga_best_json: str | os.PathLike[str],
                   chain_npz: str | os.PathLike[str], assembly: str, cal: CalibrateSettings, ps: PosteriorSettings,
                   out_csv: str | os.PathLike[str], backbone_csv: str | os.PathLike[str] | None = None) -> str:
    """Write ``identified.csv``, the posterior stage's last output, from the chain it wrote (`identified_table`).

    Which parameters and combinations the data identify, from the draws in `chain_npz`, with the
    reason when the chain has not settled (`unsettled`). Returns a line for the log.
    """
    cal = cal.resolved(json.loads(Path(ga_best_json).read_text()))
    data = read_modal(modal_csv, assembly, damping=cal.damping, backbone_csv=backbone_csv)
    with np.load(chain_npz) as z:
        names = [str(n) for n in z["sample_names"]]
        why_not = unsettled({k: z[k] for k in z.files}, names, tau_factor=ps.tau_factor)
        table, _ = identified_table(z["samples"], names, cal.space, data.q, data.f, data.zeta, m=cal.m,
                                    model=cal.model, viscous=cal.viscous, ratio=ps.constrained_ratio,
                                    why_not=why_not, weight=data.weight)
    write_csv_atomic(table, out_csv)
    return ("identified: " + ", ".join(table.loc[table["identified"], "quantity"]) + "; left to the bounds: "
            + ", ".join(table.loc[~table["identified"], "quantity"]) + (f" ({why_not})" if why_not else ""))
