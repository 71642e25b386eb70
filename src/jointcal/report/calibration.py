"""Figures of the calibration and posterior stages (PNG bytes; matplotlib's Agg canvas, no pyplot).

* `amplitude_figure` -- the paper's Fig. 3.8: measured f and zeta versus amplitude with
  the calibrated model and its 90% posterior band, one row per assembly;
* `exploration_figure` -- Figs. 3.9/3.10: scatter-plot matrix of every individual the GA
  evaluated, coloured by objective, with densities on the diagonal;
* `convergence_figure` -- best and median objective per generation;
* `corner_figure` -- posterior pairs (2-D histograms) and marginals, written here
  (no ``corner`` package).

Each returns the PNG as bytes; the workflow scripts write them with
`jointcal.io.write_bytes_atomic`.
"""
from __future__ import annotations

import io
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..calibrate.space import LOG_SCALED, PARAMS
from .summary import fmt

__all__ = ["amplitude_figure", "exploration_figure", "convergence_figure", "corner_figure"]


def _figure(width: float, height: float, dpi: float = 110):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


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
    axes = fig.subplots(n, n)
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
                ax.set_visible(False)
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
    axes = fig.subplots(d, d)
    lims = [np.percentile(samples[:, i], [0.5, 99.5]) for i in range(d)]
    lims = [(a, b) if b > a else (a - 0.5, a + 0.5) for a, b in lims]
    ref = [np.nan] * d if truth is None else [float(v) for v in truth]
    lims = [(min(a, t), max(b, t)) if np.isfinite(t) else (a, b) for (a, b), t in zip(lims, ref)]
    pts = {k: np.asarray(v, dtype=float) for k, v in (points or {}).items()}
    for v in pts.values():
        lims = [(min(a, t), max(b, t)) if np.isfinite(t) else (a, b) for (a, b), t in zip(lims, v)]
    lims = [(a - 0.03 * (b - a), b + 0.03 * (b - a)) for a, b in lims]
    lo_b, hi_b = (np.full(d, np.nan), np.full(d, np.nan)) if bounds is None else (np.asarray(bounds[0], float),
                                                                                  np.asarray(bounds[1], float))
    n_modes = 0 if modes is None else int(np.max(modes)) + 1
    styles = {k: _POINTS.get(k, dict(marker="o", color="C2")) for k in pts}
    for i in range(d):
        for j in range(d):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                ax.hist(samples[:, i], bins=bins, range=lims[i], histtype="step", color="k")
                q = np.percentile(samples[:, i], [5, 50, 95])
                if n_modes > 1:
                    ax.axvline(q[0], color="C0", ls=":", lw=0.8)
                    ax.axvline(q[2], color="C0", ls=":", lw=0.8)
                    for k in range(n_modes):
                        ax.axvline(np.median(samples[modes == k, i]), color=f"C{4 + k}", lw=1.2)
                else:
                    for v, ls in zip(q, (":", "-", ":")):
                        ax.axvline(v, color="C0", ls=ls, lw=0.8)
                for k, v in pts.items():
                    if np.isfinite(v[i]):
                        ax.axvline(v[i], color=styles[k]["color"], ls=styles[k].get("ls", "-"), lw=1.2)
                ax.set_yticks([])
            else:
                ax.hist2d(samples[:, j], samples[:, i], bins=bins, range=[lims[j], lims[i]], cmap="Greys")
                if np.isfinite(ref[i]):
                    ax.axhline(ref[i], color="C3", lw=0.8)
                for k, v in pts.items():
                    if np.isfinite(v[i]) and np.isfinite(v[j]):
                        st = styles[k]
                        ax.plot(v[j], v[i], st["marker"], color=st["color"], mfc="none" if st.get("open") else
                                st["color"], ms=8, mew=1.5)
                for b in (lo_b[i], hi_b[i]):
                    if np.isfinite(b) and lims[i][0] <= b <= lims[i][1]:
                        ax.axhline(b, color="0.4", ls="--", lw=0.9)
            for b in (lo_b[j], hi_b[j]):
                if np.isfinite(b) and lims[j][0] <= b <= lims[j][1]:
                    ax.axvline(b, color="0.4", ls="--", lw=0.9)
            if np.isfinite(ref[j]):
                ax.axvline(ref[j], color="C3", lw=0.8)
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
    if bounds is not None:
        handles.append(Line2D([], [], color="0.4", ls="--", label="prior bound"))
    fig.legend(handles=handles, loc="upper right", bbox_to_anchor=(0.99, 0.82), fontsize=9, frameon=False)
    lines = []
    if stamp is not None:
        lines.append((stamp[0], "darkgreen" if stamp[1] else "#b00000"))
    if n_modes > 1:
        lines.append((f"MULTIMODAL: {n_modes} separated modes (the overall median lies between them)", "#b00000"))
    if bounds is not None:
        q05, q95 = np.percentile(samples, [5, 95], axis=0)
        w = hi_b - lo_b
        at = [names[i] for i in range(d) if np.isfinite(w[i]) and (q05[i] - lo_b[i] < 0.01 * w[i]
                                                                      or hi_b[i] - q95[i] < 0.01 * w[i])]
        if at:
            lines.append(("at a prior bound: " + ", ".join(at), "#b36b00"))
    for k, (text, colour) in enumerate(lines):
        fig.text(0.99, 0.975 - 0.035 * k, text, ha="right", va="top", fontsize=11, color=colour, weight="bold")
    if title:
        fig.suptitle(title, fontsize=12, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    return _png(fig)
