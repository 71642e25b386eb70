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

__all__ = ["amplitude_figure", "exploration_figure", "convergence_figure", "corner_figure"]


def _figure(width: float, height: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110)
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
        row[0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return _png(fig)


def _axis_values(name: str, v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.log10(v) if LOG_SCALED.get(name, name == "objective") else v


def _axis_label(name: str) -> str:
    return f"log10 {name}" if LOG_SCALED.get(name, name == "objective") else name


def exploration_figure(history: pd.DataFrame, *, title: str = "", max_points: int = 6000) -> bytes:
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
    """
    cols = [*PARAMS, "objective"]
    h = history[history["objective"] < 1e9]
    vals = {c: _axis_values(c, h[c].to_numpy(float)) for c in cols}
    order = np.argsort(-h["objective"].to_numpy())
    thin = order[np.linspace(0, len(order) - 1, min(max_points, len(order))).astype(int)] if len(order) else order
    colour = vals["objective"][thin]
    n = len(cols)
    fig = _figure(1.6 * n, 1.6 * n)
    axes = fig.subplots(n, n)
    for i, ci in enumerate(cols):
        for j, cj in enumerate(cols):
            ax = axes[i, j]
            if i == j:
                ax.hist(vals[ci], bins=40, density=True, color="0.4")
            elif i > j:
                ax.scatter(vals[cj][thin], vals[ci][thin], c=colour, s=2, cmap="viridis", lw=0, rasterized=True)
            else:
                ax.set_visible(False)
            ax.tick_params(labelsize=6)
            if i == n - 1:
                ax.set_xlabel(_axis_label(cj), fontsize=7)
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(_axis_label(ci), fontsize=7)
            elif j != i:
                ax.set_yticklabels([])
    fig.suptitle(f"GA exploration {title} (colour: log10 objective, dark = low)".strip(), fontsize=9)
    fig.tight_layout()
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
    ax.legend(fontsize=7)
    fig.tight_layout()
    return _png(fig)


def corner_figure(samples: NDArray[np.float64], names: Sequence[str], *, truth: Sequence[float] | None = None,
                  title: str = "", bins: int = 30) -> bytes:
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
    """
    samples = np.asarray(samples, dtype=float)
    d = samples.shape[1]
    fig = _figure(1.5 * d, 1.5 * d)
    axes = fig.subplots(d, d)
    lims = [np.percentile(samples[:, i], [0.5, 99.5]) for i in range(d)]
    lims = [(a, b) if b > a else (a - 0.5, a + 0.5) for a, b in lims]
    ref = [np.nan] * d if truth is None else [float(v) for v in truth]
    lims = [(min(a, t), max(b, t)) if np.isfinite(t) else (a, b) for (a, b), t in zip(lims, ref)]
    for i in range(d):
        for j in range(d):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                ax.hist(samples[:, i], bins=bins, range=lims[i], histtype="step", color="k")
                q = np.percentile(samples[:, i], [5, 50, 95])
                for v, ls in zip(q, (":", "-", ":")):
                    ax.axvline(v, color="C0", ls=ls, lw=0.8)
                ax.set_yticks([])
            else:
                ax.hist2d(samples[:, j], samples[:, i], bins=bins, range=[lims[j], lims[i]], cmap="Greys")
                if np.isfinite(ref[i]):
                    ax.axhline(ref[i], color="C3", lw=0.8)
            if np.isfinite(ref[j]):
                ax.axvline(ref[j], color="C3", lw=0.8)
            ax.tick_params(labelsize=6)
            if i == d - 1:
                ax.set_xlabel(names[j], fontsize=7)
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(names[i], fontsize=7)
            elif j != i:
                ax.set_yticklabels([])
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return _png(fig)
