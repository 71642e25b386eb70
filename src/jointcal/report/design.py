"""The design stage's figure (PNG bytes; matplotlib's Agg canvas, no pyplot).

`design_figure`: the predicted spread against level. Per candidate level (the campaign's
rate, first direction): the 5-95% band and median over the posterior draws of the
phase-resonance frequency and damping a test would read, with the measured runs; the
expected narrowing of the quantities the next test is meant to identify and the share of
draws at which it identifies them; the recommendation and the shaker limit marked. When
the design does not apply (a force- or voltage-driven campaign) the figure shows the
measured amplitudes against level beside the posterior's range of the macroslip onset.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pandas as pd

from .calibration import _figure, _png

__all__ = ["design_figure"]


def _per_level(ranked: pd.DataFrame) -> pd.DataFrame:
    """One row per level: the read-out (rate-independent) and the best share and narrowing over its sweeps."""
    first = ranked.sort_values("rank").groupby("level_g", sort=True).head(1).set_index("level_g").sort_index()
    best = ranked.groupby("level_g")[["share_targets", "target_ratio"]].max()
    return first.drop(columns=["share_targets", "target_ratio"]).join(best)


def design_figure(rec: Mapping[str, Any], ranked: pd.DataFrame, measured: pd.DataFrame,
                  identified: pd.DataFrame) -> bytes:
    """The next-test figure of one assembly.

    Parameters
    ----------
    rec : mapping
        next_test.json's content.
    ranked : DataFrame
        next_test.csv's content.
    measured : DataFrame
        The runs in hand: level, f_hz, zeta, q_in.
    identified : DataFrame
        identified.csv (for the macroslip onset phi_max).
    """
    pm = identified.set_index("quantity").loc["phi_max"]
    if not rec.get("applicable", False) or ranked.empty:
        fig = _figure(7.0, 4.2)
        ax = fig.add_subplot(1, 1, 1)
        ax.plot(measured["level"], measured["q_in"], "o", color="k", label="measured q_in")
        ax.axhspan(pm["q05"], pm["q95"], color="tab:orange", alpha=0.25, label="phi_max, 90% posterior range")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("level (campaign's unit)")
        ax.set_ylabel("joint amplitude q (in)")
        ax.set_title(f"{rec.get('assembly', '')}: no level recommended (see next_test.md); the amplitude a test "
                     "must pass", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        return _png(fig)
    lv = _per_level(ranked)
    x = lv.index.to_numpy(float)
    r = rec["recommended"]
    fig = _figure(12.0, 4.2)
    axes = [fig.add_subplot(1, 3, i + 1) for i in range(3)]
    for ax, key, label, scale in ((axes[0], "f", "phase-resonance frequency (Hz)", 1.0),
                                  (axes[1], "zeta", "damping ratio (%)", 100.0)):
        ax.fill_between(x, scale * lv[f"{key}_q05"], scale * lv[f"{key}_q95"], color="tab:blue", alpha=0.25,
                        label="predicted, 5-95% of the draws")
        ax.plot(x, scale * lv[f"{key}_q50"], "-", color="tab:blue", lw=1.2, label="predicted median")
        col = "f_hz" if key == "f" else "zeta"
        ax.plot(measured["level"], scale * measured[col], "o", color="k", ms=4, label="measured")
        ax.set_ylabel(label)
    ax = axes[2]
    for name, style in zip(rec["targets"], ("-", "--", ":")):
        col = f"ratio_{name}"
        if col in ranked.columns:
            best = ranked.groupby("level_g")[col].max().sort_index()
            ax.plot(best.index, best.to_numpy(), style, color="tab:red", lw=1.4, label=f"{name}: expected width ratio")
    ax.set_yscale("log")
    ax.set_ylabel("90% width now / after (expected)")
    ax2 = ax.twinx()
    ax2.plot(x, 100 * lv["share_targets"], "s-", color="tab:green", ms=3, lw=1.0,
             label="draws the test identifies them at (%)")
    ax2.set_ylabel("share of posterior draws identifying the targets (%)", color="tab:green")
    ax2.set_ylim(0, 100)
    for a in axes:
        a.set_xscale("log")
        a.set_xlabel("base level (g)")
        a.axvline(r["level_g"], color="tab:purple", lw=1.5, alpha=0.7)
        a.axvline(rec["max_level_g"], color="0.4", lw=1.0, ls=":")
        a.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, loc="lower left")
    lines = ax.get_legend_handles_labels()
    more = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="upper left")
    fig.suptitle(f"{rec['assembly']}: next test {r['level_g']:g} g {r['direction']} at {r['sweep_rate_hz_per_s']:g} Hz/s "
                 f"(purple); shaker limit {rec['max_level_g']:g} g (dotted); macroslip onset phi_max "
                 f"{pm['q05']:.2g}-{pm['q95']:.2g} in (90%)", fontsize=9)
    fig.tight_layout()
    return _png(fig)
