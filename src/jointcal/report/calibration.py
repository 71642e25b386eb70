"""Figures of the calibration and posterior stages (PNG bytes; matplotlib's Agg canvas, no pyplot).

* `amplitude_figure` -- the paper's Fig. 3.8: measured f and zeta versus amplitude with
  the calibrated model and its 90% posterior band, one row per assembly;
* `exploration_figure` -- Figs. 3.9/3.10: scatter-plot matrix of every individual the GA
  evaluated, coloured by objective, with densities on the diagonal;
* `convergence_figure` -- best and median objective per generation;
* the posterior's corner plot is `jointcal.report.corner.corner_figure`.

Each returns the PNG as bytes; the workflow scripts write them with
`jointcal.io.write_bytes_atomic`.
"""
from __future__ import annotations

import io
from collections.abc import Mapping

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..calibrate.space import LOG_SCALED, PARAMS
from .summary import bound_hits, fmt, rst_escape

__all__ = ["amplitude_figure", "exploration_figure", "convergence_figure", "exploration_caption"]


def _figure(width: float, height: float, dpi: float = 110):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def _lower_triangle(fig, n: int) -> NDArray[np.object_]:
    """Axes (n, n) of a scatter-plot matrix on and below the diagonal; None above it (never created, which
    costs as much as drawing: the figure is the same as with `fig.subplots(n, n)` and the upper panels hidden)."""
    grid = fig.add_gridspec(n, n)
    axes = np.full((n, n), None, dtype=object)
    for i in range(n):
        for j in range(i + 1):
            axes[i, j] = fig.add_subplot(grid[i, j])
    return axes


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def amplitude_figure(measured: Mapping[str, pd.DataFrame], curves: Mapping[str, pd.DataFrame],
                     bands: Mapping[str, pd.DataFrame], *, model: str = "harmonic_balance") -> bytes:
    """Fig. 3.8: frequency (Hz) and damping ratio (%) versus amplitude (in), per assembly.

    Parameters
    ----------
    measured : mapping assembly -> DataFrame
        Columns q_in (in), f_hz (Hz), zeta (ratio) of the usable runs.
    curves : mapping assembly -> DataFrame
        ``model_curves.csv`` (q_in, f_hz, zeta, model): the GA optimum of both models.
    bands : mapping assembly -> DataFrame
        ``predictive.csv`` (q_in, f_q05, f_q50, f_q95, zeta_q05, zeta_q50, zeta_q95).
    model : str
        The calibrated model (drawn solid; the other model dashed).
    """
    names = list(measured)
    fig = _figure(10.0, 3.2 * len(names))
    axes = fig.subplots(len(names), 2, squeeze=False)
    for row, name in zip(axes, names):
        d, c, b = measured[name], curves[name], bands.get(name)
        for ax, key, scale, label in ((row[0], "f", 1.0, "frequency (Hz)"), (row[1], "zeta", 100.0, "damping (%)")):
            col = "f_hz" if key == "f" else "zeta"
            if b is not None:
                ax.fill_between(b["q_in"], scale * b[f"{key}_q05"], scale * b[f"{key}_q95"], color="C0", alpha=0.25,
                                lw=0, label="90% posterior band")
            for m, group in c.groupby("model", sort=False):
                ax.plot(group["q_in"], scale * group[col], color="C0" if m == model else "C1",
                        ls="-" if m == model else "--", lw=1.2, label=f"GA optimum, {m}")
            ax.plot(d["q_in"], scale * d[col], "ko", ms=4, mfc="none", label="measured")
            ax.set_xscale("log")
            ax.set_xlabel("amplitude q (in)")
            ax.set_ylabel(label)
            ax.set_title(f"{name}: {label.split(' ')[0]}")
            ax.grid(True, which="both", alpha=0.3)
        row[0].legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    return _png(fig)


def _axis_values(name: str, v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.log10(v) if LOG_SCALED.get(name, name == "objective") else v


def _axis_label(name: str) -> str:
    return f"log10 {name}" if LOG_SCALED.get(name, name == "objective") else name


def _mark_points(ax, points, xi: str | None, yi: str | None) -> None:
    """Markers of reference points (label -> (dict of values, matplotlib style)) on one panel."""
    for label, (vals, style) in points.items():
        if yi is None:  # a diagonal: a vertical line
            if xi in vals:
                ax.axvline(_axis_values(xi, np.array([vals[xi]]))[0], color=style["color"], lw=1.2,
                           ls=style.get("ls", "-"))
        elif xi in vals and yi in vals:
            ax.plot(_axis_values(xi, np.array([vals[xi]])), _axis_values(yi, np.array([vals[yi]])),
                    style["marker"], color=style["color"], mfc="none" if style.get("open") else style["color"],
                    ms=9, mew=1.6, label=label)


_POINTS = {"GA best": dict(marker="D", color="C3", open=True, ls="--"),
           "polished optimum": dict(marker="*", color="C1", ls="-")}


def exploration_figure(history: pd.DataFrame, *, title: str = "", max_points: int = 6000,
                       ga_best: dict | None = None, polished: dict | None = None,
                       bounds: dict | None = None) -> bytes:
    """Figs. 3.9/3.10: scatter-plot matrix of the GA's evaluations coloured by objective.

    Parameters
    ----------
    history : DataFrame
        ``ga_history.csv`` (generation, objective, Fs, KT, chi, beta, k, zeta_v).
    title : str
        Figure title (e.g. the assembly).
    max_points : int
        Evaluations drawn off the diagonal (evenly thinned, best ones drawn last, on top).
        The diagonal densities use every evaluation.
    ga_best, polished : dict, optional
        The GA's best individual and the polished optimum (parameters and ``objective``),
        marked on every panel (open diamond, star; lines on the diagonal).
    bounds : dict, optional
        Search bounds (param -> (lo, hi)): the axes span them, drawn as dashed grey lines.
    """
    cols = [*PARAMS, "objective"]
    h = history[history["objective"] < 1e9]
    vals = {c: _axis_values(c, h[c].to_numpy(float)) for c in cols}
    order = np.argsort(-h["objective"].to_numpy())
    thin = order[np.linspace(0, len(order) - 1, min(max_points, len(order))).astype(int)] if len(order) else order
    colour = vals["objective"][thin]
    points = {label: (v, _POINTS[label]) for label, v in (("GA best", ga_best), ("polished optimum", polished))
              if v is not None}
    lim = {c: _axis_values(c, np.asarray(bounds[c], dtype=float)) for c in PARAMS if bounds and c in bounds}
    n = len(cols)
    fig = _figure(1.35 * n + 2.2, 1.35 * n, dpi=88)  # <= ~850 px tall: Snakemake's report clips taller images
    axes = _lower_triangle(fig, n)
    sc = None
    for i, ci in enumerate(cols):
        for j, cj in enumerate(cols):
            ax = axes[i, j]
            if i == j:
                ax.hist(vals[ci], bins=40, density=True, color="0.4")
                _mark_points(ax, points, ci, None)
            elif i > j:
                sc = ax.scatter(vals[cj][thin], vals[ci][thin], c=colour, s=2, cmap="viridis", lw=0,
                                rasterized=True)
                _mark_points(ax, points, cj, ci)
                if ci in lim:
                    ax.set_ylim(*lim[ci])
                    for b in lim[ci]:
                        ax.axhline(b, color="0.5", ls="--", lw=0.8)
            else:
                continue
            if cj in lim:
                ax.set_xlim(*lim[cj])
                for b in lim[cj]:
                    ax.axvline(b, color="0.5", ls="--", lw=0.8)
            ax.tick_params(labelsize=8)
            if i == n - 1:
                ax.set_xlabel(_axis_label(cj), fontsize=9)
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(_axis_label(ci), fontsize=9)
            elif j != i:
                ax.set_yticklabels([])
    if points:
        handles, labels = axes[1, 0].get_legend_handles_labels()
        text = [f"{lab}: objective {fmt(v['objective'])}" if "objective" in v else lab
                for lab, (v, _) in points.items()]
        fig.legend(handles, text, loc="upper right", bbox_to_anchor=(0.995, 0.52), fontsize=9, frameon=False)
    fig.suptitle(f"GA exploration {title} (colour: log10 objective, dark = low; axes span the search bounds)".strip(),
                 fontsize=11)
    fig.tight_layout(rect=(0, 0, 0.88, 0.97))
    if sc is not None:  # after tight_layout, which does not handle a free-standing axes
        cax = fig.add_axes((0.89, 0.57, 0.02, 0.35))
        cb = fig.colorbar(sc, cax=cax)
        cb.set_label("log10 objective (eq. 3.9)", fontsize=9)
        cb.ax.tick_params(labelsize=8)
    return _png(fig)


def convergence_figure(logbooks: Mapping[str, pd.DataFrame]) -> bytes:
    """Best-so-far and population-median objective per generation (log scale), per assembly."""
    fig = _figure(6.0, 3.6)
    ax = fig.subplots()
    for k, (name, lb) in enumerate(logbooks.items()):
        ax.plot(lb["gen"], lb["best"], color=f"C{k}", lw=1.5, label=f"{name}: best")
        ax.plot(lb["gen"], lb["median"], color=f"C{k}", lw=1.0, ls="--", label=f"{name}: population median")
    ax.set_yscale("log")
    ax.set_xlabel("generation")
    ax.set_ylabel("objective (eq. 3.9)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _png(fig)


def exploration_caption(history: pd.DataFrame, best: Mapping, ga: Mapping[str, float], polished: Mapping[str, float],
                        bounds: Mapping[str, tuple[float, float]]) -> str:
    """The run-generated part of the GA figures' caption (reStructuredText): this run, bounds hit, macroslip.

    Parameters
    ----------
    history : DataFrame
        ``ga_history.csv`` (one row per evaluation).
    best : mapping
        ``ga_best.json`` (``generations``, ``stop_reason``, ``objective``, ``q_max_in``, ``phi_max_in``).
    ga, polished : mapping
        The GA's best point and the polished optimum (`PARAMS` and ``objective``).
    bounds : mapping
        The search bounds, name -> (lower, upper).
    """
    lines = [f"**This run** ({len(history)} evaluations, {best['generations']} generations, stopped by "
             f"{rst_escape(str(best['stop_reason']))}): GA best objective {fmt(ga['objective'])} at "
             + ", ".join(f"{rst_escape(p)} {fmt(ga[p])}" for p in PARAMS)
             + f"; polished optimum objective {fmt(best['objective'])} at "
             + ", ".join(f"{rst_escape(p)} {fmt(best[p])}" for p in PARAMS) + "."]
    for label, point in (("GA best", ga), ("polished optimum", polished)):
        hits = bound_hits(point, bounds)
        if hits:
            lines.append(f"**At a search bound** ({label}): " + ", ".join(
                f"{rst_escape(p)} at its {side} bound {fmt(bounds[p][0 if side == 'lower' else 1])}"
                for p, side in hits.items()) + ".")
    if best["q_max_in"] >= best["phi_max_in"]:
        lines.append(f"The polished optimum puts macroslip (phi\\_max {fmt(best['phi_max_in'])} in) inside the "
                     f"measured amplitudes (up to {fmt(best['q_max_in'])} in).")
    return "\n\n".join(lines) + "\n"
