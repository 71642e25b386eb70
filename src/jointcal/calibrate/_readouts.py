"""The calibration's read-outs: one point per swept run, many per ring-down, one per level's dwells.

The modal stage keeps one row per run in ``modal_properties.csv``: a sweep's read-out, a
ring-down's largest window, a dwell's own point. ``backbone.csv`` holds every amplitude-dependent
point (`jointcal.measure.testkinds`). With it, `expand` turns one unit's usable rows into the
points eq. 3.9 and the likelihood sum over, in the order data flows:

1. **Sweeps** (``f_res_method`` no test kind's estimator writes, `jointcal.measure.testkinds.estimator_of`):
   the row, as without it.
2. **Ring-downs** (any test kind's read-out: ``ringdown``, and the ring-down a dwell record holds after
   its cut): every window of the run in backbone.csv (``test`` ``ringdown``); a run without windows whose
   estimator reads each run on its own, its row.
3. **Dwells** (an estimator with a ``level_readout``: ``dwell``): each level's phase resonance
   (``q_dwell_quad_in``, ``f_dwell_quad_hz``, ``zeta_dwell_quad``), once for the level's dwells. A dwell's own point
   has its natural frequency exactly but its damping only at phase resonance (docs/physics.md
   section 8: 6% high 3% below resonance on the virtual Ministack, 30% low off resonance on the
   real beam), so the points of a level's dwells do not enter, their phase resonance does; a
   level whose phase resonance could not be read keeps its dwells' points.

**Weights.** Each read-out counts once: a swept run, a level's dwells, a ring-down along its
decay. A ring-down's k windows weigh 1/k each. They share one record (one mounting, one cut-off,
one read-out's systematic error) and overlap by half, so counted one by one a ring-down's 20-30
windows would outweigh six sweeps for what is one test; counted once, its windows still spread
over the amplitudes it swept through and fix the backbone's shape there. Eq. 3.9's 1/N becomes
1/sum(w) and each squared residual is multiplied by its weight; the likelihood raises each
point's Gaussian to its weight (`jointcal.posterior.likelihood`). With sweeps only every weight is
1 and both are what they were.

**Standard errors.** A window's read-out has its own standard errors of f and zeta (backbone.csv's
``f_se_hz``, ``zeta_se``, where the modal stage wrote them); they come along as relative scales
(`jointcal.measure.testkinds.ringdown.window_scales`, floored as the validation floors them), with the
amplitude at the window's start, q exp(pi f zeta T) for a window of T = ``window_s`` (its envelope decays at
2 pi f zeta), NaN for every other point. The polish weighs the points by them (`jointcal.calibrate.fit`).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..measure.testkinds import estimator_of
from ..measure.testkinds.dwell import STEADY
from ..measure.testkinds.ringdown import METHOD as WINDOWS
from ..measure.testkinds.ringdown import SE_COLUMNS, window_scales, window_top

__all__ = ["expand", "QUAD"]

QUAD = STEADY.level_readout  # a level's dwells' phase resonance (modal table): q, f, zeta
_VALUES = ("q_in", "f_hz", "zeta")


def _positive(table: pd.DataFrame, cols) -> np.ndarray:
    ok = np.ones(len(table), bool)
    for c in cols:
        v = pd.to_numeric(table[c], errors="coerce").to_numpy(float) if c in table else np.full(len(table), np.nan)
        ok &= np.isfinite(v) & (v > 0)
    return ok


def _windows(backbone: pd.DataFrame, run_id: str, mode) -> pd.DataFrame:
    """The run's ring-down windows in backbone.csv with positive q, f and zeta (its mode's, when named)."""
    w = backbone[(backbone["run_id"].astype(str) == run_id) & (backbone["test"] == WINDOWS)]
    if mode is not None and "mode" in w and pd.notna(mode):
        w = w[w["mode"].astype(str) == str(mode)]
    return w[_positive(w, _VALUES)]


def _scales(w: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The windows' relative scales of f and zeta (`window_scales`) and their amplitudes at their starts (in), NaN
    where backbone.csv has no lengths and standard errors."""
    if not all(c in w for c in SE_COLUMNS):
        return (np.full(len(w), np.nan),) * 3
    length, f_se, z_se = (pd.to_numeric(w[c], errors="coerce").to_numpy(float) for c in SE_COLUMNS)
    q, f, z = (w[c].to_numpy(float) for c in _VALUES)
    return (*window_scales(f, z, f_se, z_se), window_top(q, f, z, length))


def expand(rows: pd.DataFrame, backbone: pd.DataFrame, level: np.ndarray, columns: tuple[str, str, str],
           where: object) -> tuple[dict[str, np.ndarray], list[str]]:
    """One unit's usable modal rows as the calibration's points, with their weights.

    Parameters
    ----------
    rows : DataFrame
        The usable rows of modal_properties.csv (positive q, frequency and damping), in file order.
    backbone : DataFrame
        backbone.csv (``run_id, mode, test, q_in, f_hz, zeta``).
    level : ndarray, shape (len(rows),)
        The rows' drive levels (NaN without a level column).
    columns : (str, str, str)
        The modal table's amplitude, frequency and damping columns (``q_in``, ``f_res_hz``, the
        configured damping).
    where : object
        How backbone.csv is named in the notes.

    Returns
    -------
    points : dict
        ``run_id`` (str; a level's dwells joined by '+'), ``level``, ``q`` (in), ``f`` (Hz), ``zeta``,
        ``weight``, ``sigma_f``, ``sigma_zeta`` (relative scales of a window's f and zeta, `window_scales`),
        ``q_top`` (in, the amplitude at a window's start; these three NaN where the point has none): arrays of
        one length, in the table's order of runs (a ring-down's windows in time
        order), each level's dwells after them.
    notes : list of str
        What each ring-down and dwell level became, for the log.
    """
    method = rows["f_res_method"].astype(str) if "f_res_method" in rows else pd.Series("", index=rows.index)
    out: dict[str, list] = {k: [] for k in ("run_id", "level", "q", "f", "zeta", "weight", "sigma_f", "sigma_zeta",
                                            "q_top")}
    notes: list[str] = []

    def add(rid, lev, q, f, z, w, sigma=(np.nan, np.nan, np.nan)):
        n = len(np.atleast_1d(q))
        for key, v in (("run_id", [rid] * n if isinstance(rid, str) else rid), ("level", [lev] * n),
                       ("q", q), ("f", f), ("zeta", z), ("weight", [w] * n),
                       *((k, np.broadcast_to(v, (n,))) for k, v in zip(("sigma_f", "sigma_zeta", "q_top"), sigma))):
            out[key] += list(np.atleast_1d(v))

    qc, fc, zc = columns
    dwell_levels: dict[tuple, list[int]] = {}
    for i, (_, r) in enumerate(rows.iterrows()):
        rid = str(r["run_id"])
        est = estimator_of(method.iloc[i])  # a test kind's read-out (`jointcal.measure.testkinds`), None: a sweep's
        if est is not None and est.level_readout is not None:  # a level's runs hold one read-out together
            key = tuple(float(r[c]) if c in r and pd.notna(r[c]) else np.nan for c in est.level_readout)
            dwell_levels.setdefault((float(level[i]) if np.isfinite(level[i]) else np.nan, *key), []).append(i)
        if est is not None:
            w = _windows(backbone, rid, r.get("mode"))
            if len(w):
                add(rid, level[i], w[_VALUES[0]], w[_VALUES[1]], w[_VALUES[2]], 1.0 / len(w), _scales(w))
                notes.append(f"{where}: run {rid!r}: its ring-down's {len(w)} windows over "
                             f"{np.log10(w['q_in'].max() / w['q_in'].min()):.2f} decades of amplitude, one read-out "
                             f"(weight 1/{len(w)} each)")
            elif est.level_readout is None:  # no windows in the table: the run's row, as without it
                add(rid, level[i], r[qc], r[fc], r[zc], 1.0)
                notes.append(f"{where}: run {rid!r} has no ring-down windows; its modal row is its read-out")
        else:
            add(rid, level[i], r[qc], r[fc], r[zc], 1.0)
    for (lev, *quad), idx in dwell_levels.items():
        group = rows.iloc[idx]
        ids = [str(v) for v in group["run_id"]]
        if all(np.isfinite(quad)) and min(quad) > 0:
            add("+".join(ids), lev, quad[0], quad[1], quad[2], 1.0)
            notes.append(f"{where}: the {len(ids)} dwells at level {lev:g} ({', '.join(ids)}): their phase "
                         f"resonance, one read-out (q {quad[0]:.4g} in, f {quad[1]:.6g} Hz, zeta {quad[2]:.4g})")
        else:
            for _, r in group.iterrows():
                add(str(r["run_id"]), lev, r[qc], r[fc], r[zc], 1.0)
            notes.append(f"{where}: the dwells at level {lev:g} ({', '.join(ids)}) have no phase resonance; each "
                         "dwell's own point is a read-out (its damping is exact only near resonance)")
    arrays = {k: np.asarray(v, dtype=object if k == "run_id" else float) for k, v in out.items()}
    return arrays, notes
