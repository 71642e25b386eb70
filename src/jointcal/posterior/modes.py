"""Separated modes of a posterior sample: where each lies and what share of the draws it holds.

A posterior with two separated modes (e.g. one with macroslip inside the measured
amplitudes and one without) is misdescribed by its median, which can fall between them
where the posterior has no mass. `find_modes` splits the draws in two (k-means on
standardised coordinates, `scipy.cluster.vq.kmeans2`) and keeps the split only when the
density of the draws projected on the line joining the two centres has a valley between
them: at most ``dip`` times the lower of the two peaks (a histogram of the projection).
Each part is split again the same way, up to ``max_modes``.

An ensemble sampler such as emcee's stretch move mixes between separated modes only
through walkers that already sit in both, so the weights of modes found in a short or
unconverged chain reflect where the walkers started more than the posterior mass; the
report says so.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy.cluster.vq import kmeans2

__all__ = ["find_modes", "mode_labels", "modes_text"]


def _valley(t: NDArray[np.float64], *, bins: int, min_weight: float) -> tuple[float, float]:
    """Deepest valley of the histogram of `t` (N,): (valley / lower peak, cut value).

    Every bin is tried as the cut; the peaks are the highest bins on either side, and
    each side must hold at least `min_weight` of the draws. Counts are smoothed over
    3 bins against sampling noise. Ratio 1 (no valley) when no cut qualifies.
    """
    lo, hi = np.percentile(t, [0.5, 99.5])
    if not hi > lo:
        return 1.0, float(lo)
    hist, edges = np.histogram(t, bins=bins, range=(lo, hi))
    h = np.convolve(hist, np.ones(3) / 3, mode="same")
    left = np.maximum.accumulate(h)  # highest bin at or left of each bin
    right = np.maximum.accumulate(h[::-1])[::-1]
    share = np.cumsum(hist) / max(len(t), 1)  # draws at or left of each bin (within the range)
    ok = (share >= min_weight) & (1.0 - share >= min_weight)
    ok[[0, -1]] = False
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(ok, h / np.minimum(left, right), np.inf)
    v = int(np.argmin(ratio))
    return (float(ratio[v]) if np.isfinite(ratio[v]) else 1.0), float(0.5 * (edges[v] + edges[v + 1]))


def _split(z: NDArray[np.float64], *, dip: float, min_weight: float, bins: int,
           seed: int) -> NDArray[np.bool_] | None:
    """A boolean mask of one side when `z` (N, D; standardised) has two separated modes, else None.

    Directions tried: each coordinate (a gap in a marginal), the three leading principal
    axes and the line joining two k-means centres (modes separated along a combination).
    """
    if len(z) < 4 * bins:
        return None
    dirs = list(np.eye(z.shape[1]))
    _, _, vt = np.linalg.svd(z - z.mean(axis=0), full_matrices=False)
    dirs += list(vt[:3])
    for s in range(3):
        centres, lab = kmeans2(z, 2, minit="++", seed=seed + s)
        d = centres[1] - centres[0]
        if np.any(lab == 0) and np.any(lab == 1) and np.linalg.norm(d) > 0:
            dirs.append(d / np.linalg.norm(d))
    best = (dip, None, 0.0)
    for d in dirs:
        t = z @ d
        ratio, cut = _valley(t, bins=bins, min_weight=min_weight)
        if ratio <= best[0]:
            best = (ratio, d, cut)
    if best[1] is None:
        return None
    return z @ best[1] > best[2]


def mode_labels(samples: ArrayLike, *, dip: float = 0.25, min_weight: float = 0.05, max_modes: int = 4,
                bins: int = 40, seed: int = 0) -> NDArray[np.int_]:
    """Label each draw with its mode (0, 1, ...; by decreasing weight).

    Parameters
    ----------
    samples : array_like, shape (N, D)
        Draws in the coordinates where modes are looked for (e.g. log10 of the scale
        parameters); constant columns are ignored.
    dip : float
        A split is kept when the projected density's valley is at most `dip` times the
        lower of its two peaks (0.25: a clear valley; sampling noise of a flat or
        single-peaked histogram with >= 100 draws a bin stays well above it).
    min_weight : float
        Modes holding less than this share of the draws are not split off.
    max_modes : int
        Largest number of modes returned.
    bins : int
        Histogram bins of the projection.
    seed : int
        Seed of the k-means initialisation.

    Returns
    -------
    ndarray of int, shape (N,)
    """
    x = np.asarray(samples, dtype=float)
    sd = x.std(axis=0)
    keep = np.isfinite(sd) & (sd > 0)
    z = (x[:, keep] - x[:, keep].mean(axis=0)) / sd[keep] if keep.any() else np.zeros((len(x), 1))
    labels = np.zeros(len(x), dtype=int)
    queue = [0]
    n_modes = 1
    while queue and n_modes < max_modes:
        k = queue.pop(0)
        idx = np.flatnonzero(labels == k)
        side = _split(z[idx], dip=dip, min_weight=min_weight * len(x) / max(len(idx), 1), bins=bins, seed=seed)
        if side is None:
            continue
        labels[idx[side]] = n_modes
        queue += [k, n_modes]
        n_modes += 1
    counts = np.bincount(labels, minlength=n_modes)
    rank = np.empty(n_modes, dtype=int)
    rank[np.argsort(-counts, kind="stable")] = np.arange(n_modes)
    return rank[labels]


def find_modes(samples: ArrayLike, names: Sequence[str], *, labels: ArrayLike | None = None,
               **kwargs) -> pd.DataFrame:
    """Location and weight of each separated mode of a posterior sample.

    Parameters
    ----------
    samples : array_like, shape (N, D)
        Draws in physical units (modes are looked for in the same coordinates; pass
        log10 values for log-scaled parameters if that is where they are separated).
    names : sequence of str, length D
        Column names.
    labels : array_like of int, shape (N,), optional
        Mode labels from an earlier `mode_labels` call (e.g. made in other coordinates).
    **kwargs
        Passed to `mode_labels` when `labels` is not given.

    Returns
    -------
    pandas.DataFrame
        One row per mode and parameter: mode (0 = heaviest), weight (share of the draws),
        param, median, q05, q95.
    """
    x = np.asarray(samples, dtype=float)
    labels = mode_labels(x, **kwargs) if labels is None else np.asarray(labels, dtype=int)
    rows = []
    for k in range(labels.max() + 1):
        part = x[labels == k]
        q05, q50, q95 = np.percentile(part, [5, 50, 95], axis=0)
        for i, name in enumerate(names):
            rows.append(dict(mode=k, weight=len(part) / len(x), param=name, median=q50[i], q05=q05[i], q95=q95[i]))
    return pd.DataFrame(rows)


def modes_text(modes: pd.DataFrame, params: Sequence[str], *, converged: bool = True) -> str:
    """One sentence: unimodal, or each mode's weight and location (median of each parameter in `params`)."""
    n = int(modes["mode"].max()) + 1 if len(modes) else 0
    if n <= 1:
        return "The posterior has a single mode."
    parts = []
    for k, g in modes.groupby("mode"):
        g = g.set_index("param")
        loc = ", ".join(f"{p} {g.loc[p, 'median']:.3g}" for p in params if p in g.index)
        parts.append(f"mode {k + 1} ({100 * g['weight'].iloc[0]:.0f}% of the draws): {loc}")
    caveat = ("" if converged else " The chain did not converge, so these shares reflect where the walkers "
              "started more than the posterior mass.")
    return (f"The posterior is MULTIMODAL ({n} separated modes; the overall median lies between them and "
            f"describes neither): " + "; ".join(parts) + "." + caveat)
