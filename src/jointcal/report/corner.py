"""The posterior's corner plot: 1-D marginals on the diagonal, 2-D histograms below it.

Written here with matplotlib (no corner-plot dependency); used for the posterior stage's
figure (`workflow/scripts/posterior_corner.py`) of any parameter space.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from .calibration import _POINTS, _figure, _lower_triangle, _png

__all__ = ["corner_figure"]


def corner_figure(samples: NDArray[np.float64], names: Sequence[str], *, truth: Sequence[float] | None = None,
                  title: str = "", bins: int = 30, points: Mapping[str, Sequence[float]] | None = None,
                  bounds: tuple[Sequence[float], Sequence[float]] | None = None,
                  modes: NDArray[np.int_] | None = None, stamp: tuple[str, bool] | None = None) -> bytes:
    """Corner plot: 1-D marginals on the diagonal, 2-D histograms below it.

    Parameters
    ----------
    samples : ndarray, shape (S, D)
        Posterior draws in the coordinates to plot (e.g. log10 of scale parameters).
    names : sequence of str, length D
        Axis labels.
    truth : sequence of float, optional
        Reference values drawn as red lines (e.g. a synthetic campaign's truth); NaN
        entries are skipped.
    title : str
        Figure title.
    bins : int
        Histogram bins per axis.
    points : mapping label -> sequence of float (D,), optional
        "GA best" and "polished optimum" (or others) in the plotted coordinates: markers
        off the diagonal, lines on it (NaN entries skipped).
    bounds : (lower, upper), optional
        Prior bounds (D,) in the plotted coordinates: dashed grey lines, and a parameter
        whose 90% interval touches one is named in the stamp.
    modes : ndarray of int, shape (S,), optional
        Mode label of each draw (`jointcal.posterior.mode_labels`): with two or more
        modes, each mode's median is drawn on the diagonal (its own colour) instead of
        the overall median, which lies between them.
    stamp : (text, ok), optional
        Status written on the figure (green when ok, red otherwise), e.g.
        ("NOT converged: 12.9 tau", False).
    """
    samples = np.asarray(samples, dtype=float)
    d = samples.shape[1]
    fig = _figure(1.2 * d + 0.4, 1.2 * d, dpi=88)  # <= ~850 px tall: Snakemake's report clips taller images
    axes = _lower_triangle(fig, d)
    ref = np.full(d, np.nan) if truth is None else np.asarray(truth, dtype=float)
    pts = {k: np.asarray(v, dtype=float) for k, v in (points or {}).items()}
    lims = _corner_limits(samples, [ref, *pts.values()])
    lo_b, hi_b = (np.full(d, np.nan), np.full(d, np.nan)) if bounds is None else (np.asarray(bounds[0], float),
                                                                                  np.asarray(bounds[1], float))
    n_modes = 0 if modes is None else int(np.max(modes)) + 1
    styles = {k: _POINTS.get(k, dict(marker="o", color="C2")) for k in pts}
    marks = np.stack([ref, lo_b, hi_b], axis=1)  # per column: truth, lower and upper bound
    for i, j in ((i, j) for i in range(d) for j in range(i + 1)):
        _panel(axes[i, j], samples, (i, j), lims, bins, modes if n_modes > 1 else None, pts, styles, marks,
               names)
    fig.legend(handles=_corner_handles(styles, modes, n_modes, bounds is not None), loc="upper right",
               bbox_to_anchor=(0.99, 0.82), fontsize=9, frameon=False)
    _corner_stamps(fig, samples, names, stamp, n_modes, (lo_b, hi_b) if bounds is not None else None)
    if title:
        fig.suptitle(title, fontsize=12, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    return _png(fig)


def _corner_limits(samples: NDArray[np.float64], marks: Sequence[NDArray[np.float64]]) -> list[tuple[float, float]]:
    """Axis range per column: the draws' 0.5-99.5% range widened to every finite mark (truth, points), +3%."""
    lims = [np.percentile(samples[:, i], [0.5, 99.5]) for i in range(samples.shape[1])]
    lims = [(a, b) if b > a else (a - 0.5, a + 0.5) for a, b in lims]
    for v in marks:
        lims = [(min(a, t), max(b, t)) if np.isfinite(t) else (a, b) for (a, b), t in zip(lims, v)]
    return [(a - 0.03 * (b - a), b + 0.03 * (b - a)) for a, b in lims]


def _panel(ax, samples: NDArray[np.float64], where: tuple[int, int], lims: Sequence[tuple[float, float]], bins: int,
           modes: NDArray[np.int_] | None, pts: Mapping[str, NDArray[np.float64]], styles: Mapping[str, dict],
           marks: NDArray[np.float64], names: Sequence[str]) -> None:
    """Panel (row i, column j <= i): a marginal on the diagonal, a 2-D histogram below it."""
    i, j = where
    if i == j:
        _marginal(ax, samples[:, i], lims[i], bins, modes, {k: v[i] for k, v in pts.items()}, styles)
    else:
        ax.hist2d(samples[:, j], samples[:, i], bins=bins, range=[lims[j], lims[i]], cmap="Greys")
        _pair_marks(ax, tuple(marks[i]), lims[i], {k: (v[j], v[i]) for k, v in pts.items()}, styles)
    _frame(ax, (i, j, samples.shape[1]), lims, tuple(marks[j]), names)


def _marginal(ax, x: NDArray[np.float64], lim: tuple[float, float], bins: int, modes: NDArray[np.int_] | None,
              pts: Mapping[str, float], styles: Mapping[str, dict]) -> None:
    """A diagonal panel: histogram, 90% interval, the median (or each mode's) and the points as lines."""
    ax.hist(x, bins=bins, range=lim, histtype="step", color="k")
    q = np.percentile(x, [5, 50, 95])
    if modes is not None:
        ax.axvline(q[0], color="C0", ls=":", lw=0.8)
        ax.axvline(q[2], color="C0", ls=":", lw=0.8)
        for k in range(int(np.max(modes)) + 1):
            ax.axvline(np.median(x[modes == k]), color=f"C{4 + k}", lw=1.2)
    else:
        for v, ls in zip(q, (":", "-", ":")):
            ax.axvline(v, color="C0", ls=ls, lw=0.8)
    for k, v in pts.items():
        if np.isfinite(v):
            ax.axvline(v, color=styles[k]["color"], ls=styles[k].get("ls", "-"), lw=1.2)
    ax.set_yticks([])


def _pair_marks(ax, row: tuple[float, float, float], lim: tuple[float, float],
                pts: Mapping[str, tuple[float, float]], styles: Mapping[str, dict]) -> None:
    """An off-diagonal panel's marks: the row's truth and bounds as horizontal lines, the points as markers."""
    truth, lo, hi = row
    if np.isfinite(truth):
        ax.axhline(truth, color="C3", lw=0.8)
    for k, (x, y) in pts.items():
        if np.isfinite(y) and np.isfinite(x):
            st = styles[k]
            ax.plot(x, y, st["marker"], color=st["color"], mfc="none" if st.get("open") else st["color"], ms=8,
                    mew=1.5)
    for b in (lo, hi):
        if np.isfinite(b) and lim[0] <= b <= lim[1]:
            ax.axhline(b, color="0.4", ls="--", lw=0.9)


def _frame(ax, where: tuple[int, int, int], lims: Sequence[tuple[float, float]], col: tuple[float, float, float],
           names: Sequence[str]) -> None:
    """A panel's column marks (bounds, truth), limits, ticks and labels; where = (row, column, size)."""
    i, j, d = where
    truth, lo, hi = col
    for b in (lo, hi):
        if np.isfinite(b) and lims[j][0] <= b <= lims[j][1]:
            ax.axvline(b, color="0.4", ls="--", lw=0.9)
    if np.isfinite(truth):
        ax.axvline(truth, color="C3", lw=0.8)
    ax.set_xlim(*lims[j])
    if i != j:
        ax.set_ylim(*lims[i])
    ax.tick_params(labelsize=8)
    if i == d - 1:
        ax.set_xlabel(names[j], fontsize=9)
    else:
        ax.set_xticklabels([])
    if j == 0 and i > 0:
        ax.set_ylabel(names[i], fontsize=9)
    elif j != i:
        ax.set_yticklabels([])


def _corner_handles(styles: Mapping[str, dict], modes: NDArray[np.int_] | None, n_modes: int, bounds: bool) -> list:
    """The legend: interval, median (or each mode's), the points, the prior bounds."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="C0", ls=":", label="90% interval")]
    if n_modes > 1:
        handles += [Line2D([], [], color=f"C{4 + k}", label=f"median of mode {k + 1} "
                           f"({100 * np.mean(modes == k):.0f}% of draws)") for k in range(n_modes)]
    else:
        handles.append(Line2D([], [], color="C0", label="median"))
    for k, st in styles.items():
        handles.append(Line2D([], [], marker=st["marker"], color=st["color"], ls=st.get("ls", "-"),
                              mfc="none" if st.get("open") else st["color"], label=k))
    if bounds:
        handles.append(Line2D([], [], color="0.4", ls="--", label="prior bound"))
    return handles


def _corner_stamps(fig, samples: NDArray[np.float64], names: Sequence[str], stamp: tuple[str, bool] | None,
                   n_modes: int, bounds: tuple[NDArray[np.float64], NDArray[np.float64]] | None) -> None:
    """Status lines at the top right: the stamp, a multimodal warning, the parameters at a prior bound."""
    lines = []
    if stamp is not None:
        lines.append((stamp[0], "darkgreen" if stamp[1] else "#b00000"))
    if n_modes > 1:
        lines.append((f"MULTIMODAL: {n_modes} separated modes (the overall median lies between them)", "#b00000"))
    if bounds is not None:
        lo_b, hi_b = bounds
        q05, q95 = np.percentile(samples, [5, 95], axis=0)
        w = hi_b - lo_b
        at = [names[i] for i in range(len(names)) if np.isfinite(w[i]) and (q05[i] - lo_b[i] < 0.01 * w[i]
                                                                              or hi_b[i] - q95[i] < 0.01 * w[i])]
        if at:
            lines.append(("at a prior bound: " + ", ".join(at), "#b36b00"))
    for k, (text, colour) in enumerate(lines):
        fig.text(0.99, 0.975 - 0.035 * k, text, ha="right", va="top", fontsize=11, color=colour, weight="bold")
