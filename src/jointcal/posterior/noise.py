"""The noise scale of the read-outs where a campaign has no repeats, and what in the data stops a posterior.

The likelihood and the chi-square test of `jointcal.posterior.stage` weigh each run's
relative residual of frequency and damping by a noise scale. With repeated runs (or runs
at one level in both directions or at two sweep rates) it is their pooled relative
scatter (``scatter.csv``). Most campaigns have none: one run per level. A default floor
then stands in for a scatter nobody measured, and a chi-square over it says nothing.
`readout_noise` takes instead the read-outs' own scatter about the smoothest curve through
them (a quadratic in log q of log f and of log zeta, fitted by least squares): what
varies from run to run faster than any backbone can. It errs high where the measured
backbone has more shape than a quadratic (a smaller chi-square, never a false rejection
from a floor). `noise_scale` applies it per quantity where the scatter table has no
degrees of freedom. A run read at many points (a ring-down's windows) is its own smooth curve:
its points' scatter about a cubic in log q over its own amplitudes, pooled with the other runs'
scatter about one quadratic across them (a quadratic through four ring-downs over three decades
of the virtual Ministack left 0.23% in f; each ring-down's own cubic 0.01-0.04%, its windows'
read-out noise).

`data_problem` names what in the read-outs stops a posterior (two modes mixed in one
assembly, too few levels, a flat backbone) and the fix, in one sentence.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from ..calibrate.data import FREQUENCY, ModalData

__all__ = ["readout_noise", "noise_scale", "data_problem", "scale_words", "SOURCE_WORDS"]

SOURCE_WORDS = {"repeats": "the repeat scatter",
                "own": "the read-outs' own scatter about a smooth backbone (no repeated runs)",
                "floor": "the noise floor posterior.rel_std_floor (no repeats, too few levels for the read-outs' "
                         "own scatter)"}


def scale_words(sources: tuple[str, str]) -> str:
    """The noise scales' source in words: one source for both, or each named."""
    if sources[0] == sources[1]:
        return SOURCE_WORDS.get(sources[0], sources[0])
    return (f"the noise scales (frequency: {SOURCE_WORDS.get(sources[0], sources[0])}; damping: "
            f"{SOURCE_WORDS.get(sources[1], sources[1])})")


def readout_noise(q: ArrayLike, f: ArrayLike, zeta: ArrayLike, *, degree: int = 2) -> tuple[float, float, int]:
    """Relative scatter of f and zeta about a polynomial of ``degree`` in log q (their logs fitted).

    Parameters
    ----------
    q : array_like, shape (N,)
        Amplitudes, in.
    f, zeta : array_like, shape (N,)
        Resonance (Hz) and damping ratio of each run.
    degree : int
        Degree of the smooth curve.

    Returns
    -------
    sigma_f, sigma_zeta : float
        rms residual of log f and log zeta (relative), ddof = degree + 1; NaN with fewer than
        degree + 3 distinct amplitudes.
    dof : int
        Degrees of freedom (N - degree - 1), 0 when NaN.
    """
    x = np.log(np.asarray(q, dtype=float))
    n = x.size
    if np.unique(np.round(x, 9)).size < degree + 3:
        return float("nan"), float("nan"), 0
    t = (x - x.mean()) / max(float(np.ptp(x)), 1e-12)
    out = []
    for y in (np.log(np.asarray(f, dtype=float)), np.log(np.asarray(zeta, dtype=float))):
        r = np.polynomial.polynomial.polyval(t, np.polynomial.polynomial.polyfit(t, y, degree)) - y
        out.append(float(np.sqrt(np.sum(r**2) / (n - degree - 1))))
    return out[0], out[1], n - degree - 1


def _own_scatter(data: ModalData) -> tuple[float, float, int]:
    """`readout_noise` of the data; with runs of many points, each such run about its own cubic and the
    single read-outs about one quadratic, pooled over their degrees of freedom."""
    if data.weight is None:
        return readout_noise(data.q, data.f, data.zeta)
    ids = np.asarray(data.run_id, dtype=object)
    names, counts = np.unique(ids, return_counts=True)
    groups = [ids == r for r in names[counts > 1]] + [np.isin(ids, names[counts == 1])]
    ss, dof = np.zeros(2), 0
    for g, degree in zip(groups, [3] * (len(groups) - 1) + [2]):
        s_f, s_z, d = readout_noise(data.q[g], data.f[g], data.zeta[g], degree=degree)
        if d > 0:
            ss += d * np.array([s_f, s_z]) ** 2
            dof += d
    if dof == 0:
        return float("nan"), float("nan"), 0
    s_f, s_z = np.sqrt(ss / dof)
    return float(s_f), float(s_z), dof


def _dof(scatter: pd.DataFrame | None, assembly: str, quantity: str) -> int:
    if scatter is None or "n" not in scatter.columns:
        return 0
    rows = scatter[(scatter["assembly"].astype(str) == assembly) & (scatter["quantity"] == quantity)
                   & (scatter["source"] == "pooled")]
    n = pd.to_numeric(rows["n"], errors="coerce").to_numpy(float)
    return int(n[0]) if n.size and np.isfinite(n[0]) else 0


def noise_scale(data: ModalData, scatter: pd.DataFrame | None,
                floors: dict[str, float]) -> tuple[ModalData, tuple[str, str], list[str]]:
    """The data with each quantity's noise scale from its repeats, else the read-outs' own scatter.

    Parameters
    ----------
    data : ModalData
        `jointcal.calibrate.read_modal`'s result (``rel_noise`` from the repeats or the floors).
    scatter : DataFrame or None
        ``scatter.csv`` (its pooled rows' ``n`` are the repeats' degrees of freedom).
    floors : dict
        ``posterior.rel_std_floor`` ({'frequency': ..., 'damping': ...}): the smallest scales.

    Returns
    -------
    data : ModalData
        With ``rel_noise`` replaced where the scatter table has no degrees of freedom.
    sources : (str, str)
        'repeats', 'own' or 'floor', for frequency and damping (`SOURCE_WORDS`).
    notes : list of str
    """
    own_f, own_z, dof = _own_scatter(data)
    noise, sources, notes = list(data.rel_noise), [], []
    for i, (qty, key, own) in enumerate(((FREQUENCY, "frequency", own_f), (data.damping, "damping", own_z))):
        if _dof(scatter, data.assembly, qty) > 0:
            sources.append("repeats")
        elif np.isfinite(own):
            noise[i] = max(own, float(floors[key]))
            sources.append("own")
            notes.append(f"no repeated runs of {data.assembly!r} for {qty}: its noise scale is the read-outs' own "
                         f"scatter about a smooth backbone, {own:.3g} over {dof} degrees of freedom"
                         + (f" (floored at {floors[key]:g})" if own < floors[key] else ""))
        else:
            sources.append("floor")
    return replace(data, rel_noise=(float(noise[0]), float(noise[1]))), (sources[0], sources[1]), notes


def _clusters(f: np.ndarray, q: np.ndarray, level: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Two groups of resonances far apart (a gap of more than 20% and 10x either group's spread), each of two
    runs or more, that share a drive level or overlap in amplitude (a softening joint orders its runs by
    level and amplitude instead), else None."""
    o = np.argsort(f)
    lf = np.log(f[o])
    if lf.size < 4:
        return None
    gaps = np.diff(lf)
    k = int(np.argmax(gaps))
    lo, hi = o[: k + 1], o[k + 1:]
    spread = max(float(np.ptp(lf[: k + 1])), float(np.ptp(lf[k + 1:])), 1e-6)
    same_level = bool(np.intersect1d(np.round(level[lo], 9), np.round(level[hi], 9)).size)
    overlap = same_level or q[hi].max() > q[lo].min()  # a level read at both, or amplitudes both reach
    if gaps[k] > np.log(1.2) and gaps[k] > 10 * spread and overlap and min(lo.size, hi.size) >= 2:
        return lo, hi
    return None


def data_problem(data: ModalData, *, noise: tuple[float, float] | None = None,
                 noise_max: tuple[float, float] | None = None,
                 where: str = "modal_properties.csv") -> list[tuple[str, str]]:
    """What in the read-outs stops or weakens the posterior: (kind, one sentence with the fix) each.

    Kinds, in this order: 'two_modes' (the runs' f_res cluster at two frequencies more than
    20% apart at the same levels or amplitudes: two modes mixed in one assembly), 'noise' (noise
    scales at or above ``noise_max``, the posterior's stop), 'few_levels' (fewer than 3
    distinct amplitudes for a 6-parameter joint) and 'flat' (f and zeta change over the
    levels by less than twice their noise).
    """
    a, f = data.assembly, np.asarray(data.f, dtype=float)
    q = np.asarray(data.q, dtype=float)
    out = []
    two = _clusters(f, q, np.asarray(data.level, dtype=float))
    if two is not None:
        lo, hi = (np.asarray(data.run_id)[np.sort(g)] for g in two)  # in the table's order
        f_lo, f_hi = (float(np.median(f[g])) for g in two)
        out.append(("two_modes", f"{where}: the runs of assembly {a!r} read two different modes, f_res near "
                    f"{f_lo:.4g} Hz ({', '.join(lo[:4])}{', ...' if len(lo) > 4 else ''}) and near {f_hi:.4g} Hz "
                    f"({', '.join(hi[:4])}{', ...' if len(hi) > 4 else ''}) at the same levels or amplitudes, and one joint "
                    f"cannot fit both; read one mode in every run with `modal: {{mode_hz: {f_hi:.3g}}}` (or "
                    f"{f_lo:.3g}) in a config file given by --configfile, then rerun from the modal stage."))
    s = noise if noise is not None else data.rel_noise
    if noise_max is not None and not (np.all(np.isfinite(s)) and np.all(np.asarray(s) < np.asarray(noise_max))):
        out.append(("noise", f"{where}: the read-outs of assembly {a!r} scatter by {100 * s[0]:.3g}% (frequency) and "
                    f"{100 * s[1]:.3g}% (damping) from run to run, at or above posterior.noise_max ({noise_max[0]:g}, "
                    f"{noise_max[1]:g}); look in modal_properties.csv for runs read at another mode or flagged (leave "
                    "them out of the manifest), or raise posterior.noise_max if the structure really varies that much."))
    n_q = np.unique(np.round(np.log(q), 3)).size
    if n_q < 3:
        out.append(("few_levels", f"{where}: assembly {a!r} has usable runs at only {n_q} distinct amplitude(s) "
                    f"(q_in {', '.join(f'{v:.3g}' for v in np.unique(q))} in), too few to fix the backbone of a "
                    "six-parameter joint; add runs at three levels or more, over a decade of amplitude if the rig "
                    "allows."))
    df, dz = float(np.ptp(np.log(f))), float(np.ptp(np.log(np.asarray(data.zeta, dtype=float))))
    if n_q >= 2 and np.all(np.isfinite(s)) and df < 2 * s[0] and dz < 2 * s[1]:
        out.append(("flat", f"{where}: the backbone of assembly {a!r} is flat: f_res changes by {100 * df:.2g}% and "
                    f"the damping by {100 * dz:.2g}% over the levels, within twice their noise ({100 * s[0]:.2g}%, "
                    f"{100 * s[1]:.2g}%), so the joint is not seen; raise the level until the resonance drops by "
                    "several times its noise."))
    return out
