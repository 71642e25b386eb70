"""Figures of the measured modal properties: the paper's Figs. 3.5 and 3.6, and a
spectrogram with the tracked drive ridge."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..io import level_column
from ..io.contract import UNUSABLE

__all__ = ["steady_frames", "plot_envelopes", "plot_frequency_damping", "plot_spectrogram"]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path) -> None:
    """Save atomically: render to a temporary file next to the target, then rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=130, bbox_inches="tight")
    tmp.replace(path)


def steady_frames(env: pd.DataFrame, ramp_fraction: float = 0.95) -> pd.Series:
    """Drive-on frames at the steady base level (start/stop ramps excluded), as a boolean Series."""
    on = env["drive_on"].astype(bool)
    ref = np.hypot(env["ref_re"], env["ref_im"])
    level = np.median(ref[on]) if on.any() else np.nan
    return on & (ref >= ramp_fraction * level)


def plot_envelopes(table: pd.DataFrame, envs: dict[str, pd.DataFrame], path, ramp_fraction: float = 0.95) -> None:
    """Fig. 3.5: response envelopes versus drive frequency, one panel per assembly.

    Per level, the last downward sweep (the paper shows the down sweeps; the last of the
    1 g repeats); a level without a down sweep shows its last run. The start and stop
    ramps are left out: frames whose base (reference) amplitude is below `ramp_fraction`
    of its median over the drive-on frames (there the level, not the joint, sets the
    response, which would plot as vertical drops at the band's ends).
    """
    plt = _plt()
    level = level_column(table.columns) or "level_g"
    unit = level.split("_")[1]
    asms = list(dict.fromkeys(table["assembly"]))
    if not asms:  # a campaign without sweeps (dwells, ring-downs): no envelope to show
        fig, ax = plt.subplots(figsize=(5.5, 4.0))
        ax.text(0.5, 0.5, "no sweep run: no envelopes", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return
    fig, axes = plt.subplots(1, len(asms), figsize=(5.5 * len(asms), 4.0), squeeze=False, sharey=True)
    for ax, asm in zip(axes[0], asms):
        t = table[table["assembly"] == asm].sort_values("sequence")
        for lev, g in t.groupby(level, sort=True):
            down = g[g["direction"] == "down"]
            rid = (down if len(down) else g)["run_id"].iloc[-1]
            e = envs.get(rid)
            if e is None or e.empty:
                continue
            e = e[steady_frames(e, ramp_fraction)]
            ax.plot(e["f_drive_hz"], np.hypot(e["resp_re"], e["resp_im"]), lw=1.2, label=f"{lev:g} {unit}")
        ax.set_title(f"{asm}: last down sweep per level, ramps trimmed")
        ax.set_xlabel("drive frequency (Hz)")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(title="level")
    axes[0][0].set_ylabel("response envelope (g)")
    _save(fig, path)
    plt.close(fig)


def plot_frequency_damping(table: pd.DataFrame, path) -> None:
    """Fig. 3.6: resonance frequency and damping versus amplitude, both damping estimators (a series per
    assembly, or per assembly and mode where an assembly holds several)."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    keys = ["assembly", "mode"] if "mode" in table.columns and table["mode"].nunique() > table["assembly"].nunique() \
        else ["assembly"]  # one series per assembly, or per assembly and mode where one has several
    for i, (key, g) in enumerate(table.groupby(keys, sort=False)):
        asm, c = " ".join(map(str, key)), f"C{i}"
        bad = g["flags"].fillna("").str.contains(UNUSABLE)
        g = g[~bad]
        a1.semilogx(g["q_in"], g["f_res_hz"], "o", color=c, label=f"{asm}")
        a2.semilogx(g["q_in"], 100 * g["zeta_phase_resonance"], "o", color=c, label=f"{asm}: phase resonance")
        a2.semilogx(g["q_in"], 100 * g["zeta_half_power"], "s", mfc="none", color=c, label=f"{asm}: half power")
    a1.set_xlabel("relative displacement amplitude q (in)")
    a1.set_ylabel("resonance frequency (Hz)")
    a2.set_xlabel("relative displacement amplitude q (in)")
    a2.set_ylabel("damping ratio (%)")
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=8)
    _save(fig, path)
    plt.close(fig)


def plot_spectrogram(record: pd.DataFrame, env: pd.DataFrame, fs: float, n_window: int, run_id: str, path) -> None:
    """Response spectrogram (dB re 1 g) with the drive ridge tracked from the reference channel."""
    plt = _plt()
    from scipy.signal import ShortTimeFFT
    from scipy.signal.windows import hann

    x = np.nan_to_num(record["response_accel_g"].to_numpy(float))
    hop = max(1, n_window // 4, x.size // 600)  # ~600 columns: no display moire
    stft = ShortTimeFFT(hann(n_window, sym=False), hop, fs, mfft=4 * n_window, scale_to="magnitude")
    S = np.abs(stft.stft(x - np.median(x)))
    fig, ax = plt.subplots(figsize=(8, 4.2))
    ext = stft.extent(x.size)
    ax.imshow(20 * np.log10(S + 1e-9), origin="lower", aspect="auto", extent=ext, cmap="magma",
              interpolation="antialiased", vmin=20 * np.log10(S.max()) - 90)
    on = env["drive_on"].astype(bool)
    for k, ls in ((1, "-"), (2, "--"), (3, ":")):
        ax.plot(env["time_s"][on], k * env["f_drive_hz"][on], ls, color="c", lw=1.0,
                label="tracked drive" if k == 1 else f"{k}x drive")
    ax.set_ylim(0, fs / 2)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{run_id}: response spectrogram and the drive ridge")
    ax.legend(loc="upper left", fontsize=8)
    _save(fig, path)
    plt.close(fig)
