"""Figures of the discrepancy stage: residual maps, and envelopes before and after the named effect."""
from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from ..measure.testkinds.ringdown import METHOD as DECAY  # the validation frames' part of a decay's windows

__all__ = ["residual_map_figure", "before_after_figure", "decay_residual_figure", "decay_before_after_figure"]


def residual_map_figure(res: pd.DataFrame, diagnosis: Mapping, path) -> None:
    """Baseline residuals (measured over model, in repeat-scatter units) against f/f_res, per level and direction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    levels = sorted(res["level"].unique())
    cmap = plt.get_cmap("viridis", max(len(levels), 2))
    for i, lev in enumerate(levels):
        for d, ls in (("up", "-"), ("down", "--")):
            g = res[(res["level"] == lev) & (res["direction"] == d)]
            for _, r in g.groupby("run_id"):
                r = r.sort_values("f_over_fres")
                axes[0].plot(r["f_over_fres"], r["z_mag"], ls, color=cmap(i), lw=1, label=f"{lev:g} g {d}")
                axes[1].plot(r["f_over_fres"], r["z_phase"], ls, color=cmap(i), lw=1)
    h, lab = axes[0].get_legend_handles_labels()
    uniq = dict(zip(lab, h))
    axes[0].legend(uniq.values(), uniq.keys(), fontsize=8, ncol=4)
    _residual_axes(fig, axes, ("magnitude", "phase"), "repeat-scatter units", "f / f_res (measured)",
                   "measured / baseline model", diagnosis, path)


def _residual_axes(fig, axes, whats: tuple[str, str], units: str, xlabel: str, what_over_what: str,
                   diagnosis: Mapping, path) -> None:
    """A residual map's two panels labelled (the +-1 band of the scatter shaded), titled with the decision, saved."""
    import matplotlib.pyplot as plt

    for ax, what in zip(axes, whats):
        ax.axhspan(-1, 1, color="0.85", zorder=0)
        ax.set_ylabel(f"{what} residual\n({units})", fontsize=10)
        ax.tick_params(labelsize=9)
    axes[1].set_xlabel(xlabel, fontsize=10)
    axes[0].set_title(f"{diagnosis['assembly']}: {what_over_what}; decision: {diagnosis['effect']} "
                      f"({diagnosis['confidence']})", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def before_after_figure(frames_before: Mapping[str, pd.DataFrame], frames_after: Mapping[str, pd.DataFrame],
                        diagnosis: Mapping, path) -> None:
    """Measured (solid), baseline (dashed) and corrected (dotted) response envelopes of the sweeps; the frames of a
    mixed campaign's ring-downs and dwells (no swept envelope) are passed over."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    cmap = plt.get_cmap("viridis", max(len(frames_after), 2))
    for i, rid in enumerate(sorted(frames_after)):
        a = frames_after[rid]
        if not len(a) or not {"f_hz", "resp_meas_g", "resp_sim_g"} <= set(a.columns):
            continue
        a = a.sort_values("f_hz")
        ax.semilogy(a["f_hz"], a["resp_meas_g"], "-", color=cmap(i), lw=1.2, label=rid)
        ax.semilogy(a["f_hz"], a["resp_sim_g"], ":", color=cmap(i), lw=1.4)
        b = frames_before.get(rid)
        if b is not None and len(b) and {"f_hz", "resp_sim_g"} <= set(b.columns):
            b = b.sort_values("f_hz")
            ax.semilogy(b["f_hz"], b["resp_sim_g"], "--", color=cmap(i), lw=1.0)
    ax.set_xlabel("drive frequency (Hz)", fontsize=10)
    ax.set_ylabel("response envelope (g)", fontsize=10)
    ax.tick_params(labelsize=9)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(f"{diagnosis['assembly']}: measured (solid), calibrated model (dashed), with "
                 f"{diagnosis['recalibrated']['model']} (dotted); E {diagnosis['metric_before']:.2f} -> "
                 f"{diagnosis['metric_after']:.2f}", fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def decay_residual_figure(res: pd.DataFrame, diagnosis: Mapping, path) -> None:
    """A ring-down campaign's baseline residuals: f and zeta of the refit backbone over the measured, in the
    read-outs' scatter, against the amplitude, one line per run (`discrepancy.decay_stage`)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    for rid, r in res.groupby("run_id"):
        r = r.sort_values("q_in")
        axes[0].semilogx(r["q_in"], r["r_f"], "o-", ms=3, lw=1, label=str(rid))
        axes[1].semilogx(r["q_in"], r["r_zeta"], "o-", ms=3, lw=1)
    axes[0].legend(fontsize=7)
    _residual_axes(fig, axes, ("frequency", "damping"), "read-out scatter units", "amplitude q (in)",
                   "baseline backbone / measured ring-downs", diagnosis, path)


def decay_before_after_figure(frames_before: Mapping[str, pd.DataFrame], frames_after: Mapping[str, pd.DataFrame],
                              diagnosis: Mapping, path) -> None:
    """Measured (points), calibrated (dashed) and corrected (dotted) ring-downs' f(q) and zeta(q), each model's
    decay time-simulated from the record's state at the cut and read by the same estimator."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5), constrained_layout=True)
    cmap = plt.get_cmap("viridis", max(len(frames_after), 2))
    for i, rid in enumerate(sorted(frames_after)):
        for j, frames in enumerate((frames_after, frames_before)):
            a = frames.get(rid)
            if a is None or "part" not in a or not (a["part"] == DECAY).any():
                continue
            a = a[a["part"] == DECAY].sort_values("q_meas_in")
            for ax, col in zip(axes, ("f", "zeta")):
                meas, sim = (f"{col}_meas_hz", f"{col}_sim_hz") if col == "f" else ("zeta_meas", "zeta_sim")
                if j == 0:
                    ax.semilogx(a["q_meas_in"], a[meas], "o", ms=3, color=cmap(i), label=rid)
                ax.semilogx(a["q_meas_in"], a[sim], ":" if j == 0 else "--", color=cmap(i), lw=1.2)
    axes[0].set_ylabel("frequency (Hz)", fontsize=10)
    axes[1].set_ylabel("damping ratio", fontsize=10)
    for ax in axes:
        ax.set_xlabel("amplitude q (in)", fontsize=10)
        ax.tick_params(labelsize=9)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{diagnosis['assembly']}: measured (points), calibrated model (dashed), with "
                 f"{diagnosis['recalibrated']['model']} (dotted); E {diagnosis['metric_before']:.2f} -> "
                 f"{diagnosis['metric_after']:.2f}", fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def table_3_2_corrected_html(best: Mapping[str, Mapping], diagnoses: Mapping[str, Mapping]) -> str:
    """Table 3.2 with the paper's model (the calibration's optimum on eq. 3.9) and the corrected one.

    best : assembly -> ga_best.json; diagnoses : assembly -> diagnosis.json.
    """
    from ..calibrate.space import PARAMS, UNITS

    head = "".join(f"<th>{p} ({UNITS[p]})</th>" for p in PARAMS)
    rows = []
    for a, d in diagnoses.items():
        b = best[a]
        rec = d["recalibrated"]
        eff = ", ".join(f"{k} = {v['value']:.4g} {v['unit']}" for k, v in rec["effect_parameters"].items()) or "-"
        rows.append(f"<tr><td>{a}</td><td>paper's model (eq. 3.9 optimum)</td>"
                    + "".join(f"<td>{b[p]:.4g}</td>" for p in PARAMS) + f"<td>-</td><td>{d['metric_before']:.2f}</td></tr>")
        rows.append(f"<tr><td>{a}</td><td>corrected: {rec['model']} ({d['effect']}, {d['confidence']})</td>"
                    + "".join(f"<td>{rec['joint_parameters'][p]['value']:.4g}"
                              + ("<br><small>90%: {:.3g}-{:.3g}</small>".format(*rec["joint_parameters"][p]["interval_90"])
                                 if rec["joint_parameters"][p].get("interval_90") else "") + "</td>" for p in PARAMS)
                    + f"<td>{eff}</td><td>{d['metric_after']:.2f}</td></tr>")
    return ("<html><head><meta charset='utf-8'><style>td,th{padding:3px 8px;border-bottom:1px solid #ccc;"
            "font-family:sans-serif;font-size:13px}</style></head><body>"
            "<h3>Table 3.2: the paper's model and the corrected one</h3><table><tr><th>assembly</th><th>model</th>"
            + head + "<th>effect</th><th>validation E</th></tr>" + "".join(rows) + "</table>"
            "<p>E: validation envelope error, time simulation driven by the measured reference records "
            "(1 = the measured repeat scatter). 90%: the corrected model's posterior interval (emcee on the "
            "envelopes; approximate, see diagnosis.json's recalibrated.method).</p></body></html>")
