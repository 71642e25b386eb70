"""Table 3.2 reproduced (GA optimum and posterior median with q05-q95), and QSMA versus harmonic balance.

Pure functions from the stages' outputs (``ga_best.json`` dicts, ``summary.csv`` tables)
to tidy tables and a markdown rendering.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from ..calibrate.objective import predict
from ..calibrate.space import PARAMS, UNITS

__all__ = ["table_3_2", "table_3_2_markdown", "qsma_vs_harmonic_balance", "qsma_at_measured"]


def table_3_2(ga_best: Mapping[str, Mapping], summaries: Mapping[str, pd.DataFrame],
              identified: Mapping[str, pd.DataFrame] | None = None, *,
              params: Sequence[str] = PARAMS) -> pd.DataFrame:
    """Table 3.2: per assembly and parameter, the GA optimum and the posterior median [q05, q95].

    Parameters
    ----------
    ga_best : mapping assembly -> dict
        Contents of each ``ga_best.json``.
    summaries : mapping assembly -> DataFrame
        Each ``summary.csv`` (may miss assemblies: their posterior columns are NaN).
    identified : mapping assembly -> DataFrame, optional
        Each ``identified.csv`` (`jointcal.posterior.identified`): which parameters the data
        identify (column identified; None where not given).
    params : sequence of str
        The parameters tabulated: the joint's six, or a grown space's names (their units
        from ``summary.csv``).

    Returns
    -------
    pandas.DataFrame
        Columns assembly, param, unit, ga_optimum, posterior_median, posterior_q05,
        posterior_q95, width_ratio, constrained, identified.
    """
    rows = []
    for name, best in ga_best.items():
        s = summaries.get(name)
        s = s.set_index("param") if s is not None else None
        ident = None if not identified or name not in identified else identified[name].set_index("quantity")
        for p in params:
            post = s.loc[p] if s is not None and p in s.index else None
            unit = UNITS[p] if p in UNITS else "-" if post is None else str(post["unit"])
            rows.append(dict(assembly=name, param=p, unit=unit, ga_optimum=float(best[p]),
                             posterior_median=np.nan if post is None else float(post["median"]),
                             posterior_q05=np.nan if post is None else float(post["q05"]),
                             posterior_q95=np.nan if post is None else float(post["q95"]),
                             width_ratio=np.nan if post is None else float(post["width_ratio"]),
                             constrained=None if post is None else bool(post["constrained"]),
                             identified=None if ident is None else bool(ident.loc[p, "identified"])))
    return pd.DataFrame(rows)


def _g(v: float) -> str:
    if not np.isfinite(v):
        return "-"
    if v == 0 or 1e-3 <= abs(v) < 1e4:
        return f"{v:.4g}" if abs(v) >= 1 else f"{v:.3g}"
    mant, exp = f"{v:.3e}".split("e")
    return f"{float(mant):.3g}e{int(exp)}"


def _free(r: pd.Series) -> bool:
    """Left to the bounds: by identified.csv where the table has it, else by the posterior's width ratio."""
    flag = r.get("identified")
    if flag is not None and not pd.isna(flag):
        return not bool(flag)
    return r["constrained"] is False or r["constrained"] == False  # noqa: E712


def table_3_2_markdown(table: pd.DataFrame) -> str:
    """Markdown rendering in the paper's layout: one row per assembly and estimate, one column per parameter.

    Posterior cells read ``median [q05, q95]``; a parameter the data leave to the bounds
    (identified.csv, or else a posterior 90% width >= half the prior width) reads "not
    identified" with the range the bounds leave it, in every row: the GA optimum is given
    for the identified parameters only, as one member of the posterior's set.
    """
    units = dict(zip(table["param"], table["unit"]))  # the table's parameters, in its order
    params = list(units)
    head = "| assembly | estimate | " + " | ".join(f"{p} ({units[p]})" for p in params) + " |"
    lines = [head, "|" + "---|" * (len(params) + 2)]
    for name, g in table.groupby("assembly", sort=False):
        g = g.set_index("param")
        free = {p: _free(g.loc[p]) for p in params}
        cells = []
        for p in params:
            r = g.loc[p]
            cells.append(f"not identified (spans {_g(r['posterior_q05'])} to {_g(r['posterior_q95'])})" if free[p] else
                         f"{_g(r['posterior_median'])} [{_g(r['posterior_q05'])}, {_g(r['posterior_q95'])}]")
        lines.append(f"| {name} | posterior median [q05, q95] | " + " | ".join(cells) + " |")
        member = ["-" if free[p] else _g(g.loc[p, "ga_optimum"])
                  if g.loc[p, "posterior_q05"] <= g.loc[p, "ga_optimum"] <= g.loc[p, "posterior_q95"]
                  or not np.isfinite(g.loc[p, "posterior_q05"]) else "outside the 90% interval" for p in params]
        lines.append(f"| {name} | GA optimum (one member of the posterior's set) | " + " | ".join(member) + " |")
    lines.append("")
    lines.append("Not identified: the data leave the parameter to the bounds; no value of it is given, only the range "
                 "the bounds and the identified combinations leave it.")
    return "\n".join(lines) + "\n"


def qsma_vs_harmonic_balance(theta: Mapping[str, float], q: ArrayLike, *, m: float,
                             viscous: str = "dashpot") -> pd.DataFrame:
    """QSMA minus harmonic-balance frequency and damping of one calibrated joint.

    Parameters
    ----------
    theta : mapping
        Fs (lbf), KT (lbf/in), chi, beta, k (lbf/in), zeta_v.
    q : array_like, shape (N,)
        Amplitudes, in (e.g. the measured ones).
    m : float
        Slug mass, lbf s^2/in.
    viscous : str
        Viscous convention.

    Returns
    -------
    pandas.DataFrame
        Columns q_in, f_qsma_hz, f_hb_hz, df_percent (100 (f_qsma/f_hb - 1)), zeta_qsma,
        zeta_hb, dzeta_percent.
    """
    q = np.asarray(q, dtype=float)
    t = np.array([[theta[p] for p in PARAMS]], dtype=float)
    fq, zq = predict(t, q, m=m, model="qsma", viscous=viscous)  # type: ignore[arg-type]
    fh, zh = predict(t, q, m=m, model="harmonic_balance", viscous=viscous)  # type: ignore[arg-type]
    return pd.DataFrame({"q_in": q, "f_qsma_hz": fq[0], "f_hb_hz": fh[0], "df_percent": 100 * (fq[0] / fh[0] - 1),
                         "zeta_qsma": zq[0], "zeta_hb": zh[0], "dzeta_percent": 100 * (zq[0] / zh[0] - 1)})


def qsma_at_measured(theta: Mapping[str, float], data, assembly: str, *, m: float,
                     viscous: str = "dashpot") -> pd.DataFrame:
    """`qsma_vs_harmonic_balance` at one unit's measured amplitudes: the mean q_in of each level.

    Parameters
    ----------
    theta : mapping
        The calibrated joint (as `qsma_vs_harmonic_balance`).
    data : jointcal.calibrate.ModalData
        The unit's read-outs (``q``, in; ``level``; ``run_id``).
    assembly : str
        The unit's name, the table's first column.
    m : float
        Slug mass (or modal mass), lbf s^2/in.
    viscous : str
        Viscous convention.

    Returns
    -------
    pandas.DataFrame
        ``assembly``, ``level`` (or ``run_id`` where a run has no level: one row per run), then the
        columns of `qsma_vs_harmonic_balance`.
    """
    by_level = pd.notna(data.level).all()
    q = pd.Series(data.q).groupby(data.level if by_level else list(data.run_id), sort=by_level).mean()
    t = qsma_vs_harmonic_balance(theta, q.to_numpy(), m=m, viscous=viscous)
    t.insert(0, "assembly", assembly)
    t.insert(1, "level" if by_level else "run_id", q.index.to_numpy())
    return t
