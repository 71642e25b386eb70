"""Rank the candidates and recommend the cheapest test that identifies the targets; say it in words.

Rule (`RULE`, written once and quoted in the outputs), in two steps, since the level sets
the physics a test reaches and the sweep rate its cost and read-out quality:

1. The level: the lowest level at which some candidate identifies every target (Fs and
   the KT/k split, or whatever the data leave free) at ``confidence`` of the posterior
   draws (least force on the shaker, least wear of the interface in macroslip); when no
   level does, the level with the largest share of draws identifying them.
2. At that level, the cheapest sweep (shortest, then the first of ``directions``) whose
   share is within one binomial standard error of the level's best: faster sweeps lose
   the draws whose read-out would no longer be quasi-steady.

Shares count only draws whose read-out is a quasi-steady phase resonance. The other
candidates are ranked the same way: levels in that order, sweeps within a level likewise.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from .narrowing import CRITERION, depth_labels

__all__ = ["RULE", "rank", "recommendation", "next_test_markdown"]

RULE = ("the lowest level at which a test identifies every target at the configured confidence of the posterior "
        "draws (else the level with the largest share of draws identifying them), then at that level the shortest "
        "sweep whose share is within one binomial standard error of the level's best")


def rank(table: pd.DataFrame, targets: Sequence[str], confidence: float, directions: Sequence[str],
         n_draws: int) -> pd.DataFrame:
    """The candidate table sorted by `RULE`, with target_ratio, identifies and rank (1 = recommended) added."""
    t = table.copy()
    t["target_ratio"] = (np.exp(np.mean([np.log(t[f"ratio_{n}"]) for n in targets], axis=0)) if targets
                         else np.exp(t["eig_nats"]))
    share = t["share_targets"].fillna(0.0) if targets else t["eig_nats"] * 0.0
    t["identifies"] = (share >= confidence) if targets else False
    per_level = pd.DataFrame({"level_g": t["level_g"], "share": share, "ratio": t["target_ratio"],
                              "hit": t["identifies"]}).groupby("level_g").max()
    level_key = pd.DataFrame({"i": ~per_level["hit"], "s": np.where(per_level["hit"], 0.0, -per_level["share"]),
                              "r": np.where(per_level["hit"], 0.0, -per_level["ratio"]),
                              "l": per_level.index.to_numpy()}, index=per_level.index)
    level_order = {lv: i for i, lv in enumerate(level_key.sort_values(list(level_key.columns), kind="stable").index)}
    top = t["level_g"].map(per_level["share"])
    se = np.sqrt(top * (1.0 - top) / n_draws)
    order = {d: i for i, d in enumerate(directions)}
    key = pd.DataFrame({"l": t["level_g"].map(level_order), "near": share < top - se, "d": t["duration_s"],
                        "o": t["direction"].map(order)})
    idx = key.sort_values(list(key.columns), kind="stable").index
    t = t.loc[idx].reset_index(drop=True)
    t.insert(0, "rank", np.arange(1, len(t) + 1))
    return t


def _g(v: float) -> str:
    return "-" if v is None or not np.isfinite(v) else (f"{v:.3g}" if abs(v) < 1e4 else f"{v:.2e}")


def recommendation(ranked: pd.DataFrame, per_quantity: pd.DataFrame, *, targets: Sequence[str], confidence: float,
                   reported: Sequence[str], assembly: str, max_level_g: float) -> dict[str, Any]:
    """next_test.json's content for the first-ranked candidate.

    ``predicted_width_ratio``: the expected narrowing (geometric mean over the draws) of each
    quantity's 90% width in the sampling space, now over after; the same conditional on the
    test identifying the targets or not, the share of draws at which it does, and the widths
    now and after.
    """
    best = ranked.iloc[0]
    pq = per_quantity[(per_quantity["level_g"] == best["level_g"]) & (per_quantity["direction"] == best["direction"])
                      & (per_quantity["sweep_rate_hz_per_s"] == best["sweep_rate_hz_per_s"])].set_index("quantity")
    return {
        "assembly": assembly, "applicable": True,
        "recommended": {"level_g": float(best["level_g"]), "direction": str(best["direction"]),
                        "sweep_rate_hz_per_s": float(best["sweep_rate_hz_per_s"]),
                        "band_hz": [float(best["f_lo_hz"]), float(best["f_hi_hz"])],
                        "duration_s": float(best["duration_s"])},
        "identifies_targets": bool(best["identifies"]), "targets": list(targets),
        "share_of_draws_identifying_targets": float(best["share_targets"]), "confidence": confidence,
        "max_level_g": max_level_g,
        "predicted_width_ratio": {n: float(pq.loc[n, "ratio"]) for n in reported},
        "predicted_width_ratio_if_identified": {n: float(pq.loc[n, "ratio_if_identified"]) for n in reported},
        "predicted_width_ratio_if_not": {n: float(pq.loc[n, "ratio_if_not"]) for n in reported},
        "share_identified": {n: float(pq.loc[n, "share_identified"]) for n in reported},
        "width_now": {n: float(pq.loc[n, "width_now"]) for n in reported},
        "width_after": {n: float(pq.loc[n, "width_after"]) for n in reported},
        "width_units": "decades (log10) for Fs, KT, beta, k, zeta_v, K0, KT/k; linear for chi",
        "predicted_width_ratio_by_depth": {
            "depth": "amplitude the test reaches over the macroslip onset phi_max (eq. 3.7), per posterior draw",
            "bins": depth_labels(),
            "share_of_draws": [float(pq[f"share_depth_{b}"].iloc[0]) for b in depth_labels()],
            **{n: [float(pq.loc[n, f"ratio_depth_{b}"]) for b in depth_labels()] for n in reported}},
        "predicted_readout": {"f_hz": [float(best["f_q05"]), float(best["f_q50"]), float(best["f_q95"])],
                              "zeta": [float(best["zeta_q05"]), float(best["zeta_q50"]), float(best["zeta_q95"])],
                              "q_in_median": float(best["q_q50"]), "peak_response_g": [float(best["peak_g_q50"]),
                                                                                      float(best["peak_g_q95"])],
                              "eta_q95": float(best["eta_q95"]), "share_in_macroslip": float(best["macroslip"]),
                              "share_quasi_steady": float(best["valid"])},
        "expected_information_gain_nats": float(best["eig_nats"]),
        "criterion": CRITERION, "rule": RULE,
    }


def _factor(width_decades: float) -> str:
    """A log10 width as 'within a factor x' (the 90% interval's upper over lower end)."""
    return f"a factor {10 ** width_decades:.3g}" if np.isfinite(width_decades) else "-"


def next_test_markdown(rec: Mapping[str, Any], ranked: pd.DataFrame, *, words_now: str, top: int = 8) -> str:
    """next_test.md: the recommendation, why (`words_now`: what the runs in hand fix), what it would show,
    and the best `top` candidates."""
    r = rec["recommended"]
    lines = [f"# Next test: assembly {rec['assembly']}", "",
             f"**Recommended: a {r['level_g']:g} g base sweep, {r['direction']}, at {r['sweep_rate_hz_per_s']:g} Hz/s "
             f"({r['duration_s']:.1f} s over {r['band_hz'][0]:g}-{r['band_hz'][1]:g} Hz).**", "", words_now, ""]
    p = rec["predicted_readout"]
    tg = rec["targets"]
    lines.append(f"What it would measure (posterior draws through the steady-state model, 5-95%): phase resonance at "
                 f"{_g(p['f_hz'][1])} Hz [{_g(p['f_hz'][0])}, {_g(p['f_hz'][2])}], damping {_g(p['zeta'][1])} "
                 f"[{_g(p['zeta'][0])}, {_g(p['zeta'][2])}], joint amplitude about {_g(p['q_in_median'])} in, peak response "
                 f"{_g(p['peak_response_g'][0])} g (95% of draws below {_g(p['peak_response_g'][1])} g). The joint passes "
                 f"macroslip for {100 * p['share_in_macroslip']:.0f}% of the draws; the read-out is quasi-steady "
                 f"(eta below modal.eta_max) for {100 * p['share_quasi_steady']:.0f}%. Check the rig against the 95% "
                 "peak response: the draws with the smallest slip force the data allow slip through at high levels.")
    lines.append("")
    if tg:
        share = rec["share_of_draws_identifying_targets"]
        names = " and ".join(tg)
        ri, rn = rec["predicted_width_ratio_if_identified"], rec["predicted_width_ratio_if_not"]
        wn = rec["width_now"]
        if rec["identifies_targets"]:
            lines.append(f"It identifies {names} at {100 * share:.0f}% of the posterior draws (at least the required "
                         f"{100 * rec['confidence']:.0f}%), the lowest level and shortest sweep that do.")
        else:
            lines.append(f"No candidate up to the shaker limit of {rec['max_level_g']:g} g identifies {names} at "
                         f"{100 * rec['confidence']:.0f}% of the posterior draws; this one does at the largest share, "
                         f"{100 * share:.0f}% (the draws whose macroslip starts below the amplitude it reaches). The "
                         "new run shows which case holds: past macroslip its frequency and damping leave the microslip "
                         "power law of the runs in hand.")
        lines.append("")
        for n in tg:
            w1 = wn[n] / ri[n] if np.isfinite(ri[n]) else np.nan
            lines.append(f"- {n}: now known within {_factor(wn[n])}; if the test identifies it, within "
                         f"{_factor(w1)} (width ratio {_g(ri[n])}); if not, ratio {_g(rn[n])}; expected over the "
                         f"draws {_g(rec['predicted_width_ratio'][n])}.")
        bd = rec["predicted_width_ratio_by_depth"]
        lines += ["", "The further past macroslip the test goes, the more it narrows (the recalibrated posterior will "
                  "show where phi_max lies, so hold the outcome against its row):", "",
                  "| amplitude reached / phi_max | share of draws | " + " | ".join(f"{n} ratio" for n in tg) + " |",
                  "|---|---|" + "---|" * len(tg)]
        for k, b in enumerate(bd["bins"]):
            if bd["share_of_draws"][k] > 0:
                lines.append(f"| {b} | {100 * bd['share_of_draws'][k]:.0f}% | "
                             + " | ".join(_g(bd[n][k]) for n in tg) + " |")
    lines += ["", "Expected width ratios (now over after, 90% intervals in the sampling space): "
              + ", ".join(f"{n} {_g(v)}" for n, v in rec["predicted_width_ratio"].items()) + ".",
              f"Expected information gain {rec['expected_information_gain_nats']:.2f} nats.", "",
              f"Criterion: {rec['criterion']}.", "", f"Rule: {rec['rule']}.", "",
              "| rank | level (g) | direction | rate (Hz/s) | s | share identifying | " + " | ".join(
                  f"{n} ratio" for n in (tg or ["Fs"])) + " | EIG (nats) |",
              "|---|---|---|---|---|---|" + "---|" * len(tg or ["Fs"]) + "---|"]
    for c in ranked.head(top).itertuples():
        cells = " | ".join(_g(ranked.loc[c.Index, f"ratio_{n}"]) for n in (tg or ["Fs"]))
        lines.append(f"| {c.rank} | {c.level_g:g} | {c.direction} | {c.sweep_rate_hz_per_s:g} | {c.duration_s:.1f} | "
                     f"{100 * (c.share_targets if np.isfinite(c.share_targets) else 0):.0f}% | {cells} | "
                     f"{c.eig_nats:.2f} |")
    return "\n".join(lines) + "\n"
