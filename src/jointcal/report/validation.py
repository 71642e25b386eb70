"""Fig. 3.11 of the validation stage (PNG bytes; matplotlib's Agg canvas, no pyplot).

`validation_figure`: measured (solid) and simulated (dashed) response envelopes of the
calibrated model driven by each run's measured base record, one colour per level, the
posterior predictive band shaded; magnitude in the first row, phase of response/base in
the second, one column per assembly.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..io.contract import LEVEL, excitation_kind
from ..io.testkinds import swept_mask
from .calibration import _figure, _png

__all__ = ["validation_figure"]


def _trace_panel(ax, traces: Mapping[str, pd.DataFrame], runs: pd.DataFrame, unit: str) -> None:
    """Response envelopes in time near the mode, measured (solid) and simulated (dashed), per level."""
    from matplotlib import colormaps

    cmap = colormaps["viridis"]
    shown = [r for r in runs.sort_values("level").itertuples(index=False) if r.run_id in traces]
    for i, r in enumerate(shown):
        d = traces[r.run_id]
        c = cmap(0.85 * i / max(1, len(shown) - 1))
        ax.plot(d["time_s"], d["resp_meas_g"], "-", color=c, lw=1.2, label=f"{r.level:g} {unit}")
        ax.plot(d["time_s"], d["resp_sim_g"], "--", color=c, lw=1.0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("response envelope near the mode (g)")
    ax.set_title("the transient: passage through resonance and ring-down", fontsize=9)
    ax.grid(True, alpha=0.3)


def _pick(metrics: pd.DataFrame) -> pd.DataFrame:
    """One swept run per (level, direction): the first usable one in test order (dwells and ring-downs have
    no envelope over frequency)."""
    m = metrics[metrics["n_frames"] > 0]
    if "test" in m:
        m = m[swept_mask(m["test"])]
    return m.sort_values("sequence").groupby(["level", "direction"], sort=True).head(1)


def _unit(metrics: pd.DataFrame) -> tuple[str, str]:
    """(level unit, reference name) of a metrics table's runs."""
    kind = excitation_kind(c for c in metrics.columns if metrics[c].notna().any())
    return LEVEL[kind].split("_", 1)[1], kind


def validation_figure(frames: Mapping[str, Mapping[str, pd.DataFrame]], metrics: Mapping[str, pd.DataFrame],
                      errors: Mapping[str, float], *, direction: str = "up",
                      traces: Mapping[str, Mapping[str, pd.DataFrame]] | None = None) -> bytes:
    """Fig. 3.11: envelopes versus drive frequency (Hz), per assembly, for the runs swept ``direction``.

    Parameters
    ----------
    frames : mapping assembly -> (run_id -> DataFrame)
        The stage's envelope tables (f_hz, mag_meas_db, mag_sim_db, phase_meas_deg,
        phase_sim_deg, in_band; optional mag_q05_db/mag_q95_db, phase_q05_deg/phase_q95_deg).
    metrics : mapping assembly -> DataFrame
        The stage's metrics.csv (run_id, level and its level_g / level_lbf / level_V column, direction,
        sequence, n_frames).
    errors : mapping assembly -> float
        E of each assembly (shown in the titles).
    direction : {'up', 'down'}
        Sweep direction shown (the other one shows the same picture within the fold).
    traces : mapping assembly -> (run_id -> DataFrame), optional
        Force- and voltage-driven runs' response envelopes in time (time_s, resp_meas_g,
        resp_sim_g; `jointcal.validate.runs.time_envelopes`): a third row of panels, since a
        chirp faster than the mode holds few drive-frequency frames near resonance.

    Returns
    -------
    bytes
        PNG. Magnitude: response amplitude (g) = |response/reference| x the level (g, lbf or V).
    """
    from matplotlib import colormaps

    names = list(frames)
    rows = 3 if traces and any(traces.get(a) for a in names) else 2
    fig = _figure(5.2 * max(1, len(names)), 3.6 * rows)
    axes = fig.subplots(rows, max(1, len(names)), squeeze=False)
    for j, asm in enumerate(names):
        runs = _pick(metrics[asm])
        runs = runs[runs["direction"] == direction] if (runs["direction"] == direction).any() else runs
        unit, ref = _unit(metrics[asm])
        levels = sorted(runs["level"].unique())
        cmap = colormaps["viridis"]
        ax_m, ax_p = axes[0, j], axes[1, j]
        for i, r in enumerate(runs.sort_values("level").itertuples(index=False)):
            d = frames[asm][r.run_id]
            d = d[d["in_band"]].sort_values("f_hz")
            c = cmap(0.85 * i / max(1, len(levels) - 1))
            scale = float(r.level)
            f = d["f_hz"].to_numpy()
            ax_m.plot(f, scale * 10 ** (d["mag_meas_db"] / 20), "-", color=c, lw=1.4, label=f"{r.level:g} {unit}")
            ax_m.plot(f, scale * 10 ** (d["mag_sim_db"] / 20), "--", color=c, lw=1.2)
            ax_p.plot(f, d["phase_meas_deg"], "-", color=c, lw=1.4)
            ax_p.plot(f, d["phase_sim_deg"], "--", color=c, lw=1.2)
            lo_m = [k for k in d.columns if k.startswith("mag_q")]
            lo_p = [k for k in d.columns if k.startswith("phase_q")]
            if len(lo_m) == 2 and d[lo_m[0]].notna().any():
                ax_m.fill_between(f, scale * 10 ** (d[lo_m[0]] / 20), scale * 10 ** (d[lo_m[1]] / 20), color=c,
                                  alpha=0.25, lw=0)
                ax_p.fill_between(f, d[lo_p[0]], d[lo_p[1]], color=c, alpha=0.25, lw=0)
        ax_m.set_yscale("log")
        ax_m.set_title(f"{asm} ({direction} sweeps): E = {errors.get(asm, np.nan):.2f}", fontsize=10)
        ax_m.set_ylabel("response envelope (g)")
        ax_p.set_ylabel(f"phase of response/{ref} (deg)")
        ax_p.set_xlabel("drive frequency (Hz)")
        ax_m.plot([], [], "k-", label="measured")
        ax_m.plot([], [], "k--", label="calibrated model")
        ax_m.fill_between([], [], [], color="k", alpha=0.25, label="posterior band")
        ax_m.legend(fontsize=7, loc="upper left")
        ax_m.sharex(ax_p)
        for ax in (ax_m, ax_p):
            ax.grid(True, alpha=0.3)
        if rows == 3:
            _trace_panel(axes[2, j], (traces or {}).get(asm, {}), runs, unit)
    fig.tight_layout()
    return _png(fig)
