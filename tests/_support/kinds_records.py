"""Test helpers (not jointcal code): a linear mode's dwell and ring-down records in closed form, and a campaign."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.units import G

FN, ZETA, GAIN = 20.3, 0.02, 0.02  # Hz, -, response displacement per volt at zero frequency (in/V)


def linear_frf(f: np.ndarray | float, fn: float = FN, zeta: float = ZETA) -> np.ndarray:
    """Closed-form acceleration (g) per drive volt of the linear mode: -w^2 GAIN wn^2 / (wn^2 - w^2 + 2i zeta wn w) / G.
    """
    w, wn = 2 * np.pi * np.asarray(f, float), 2 * np.pi * fn
    return -w**2 * GAIN * wn**2 / (wn**2 - w**2 + 2j * zeta * wn * w) / G


def linear_dwell(fs: float, f_d: float, level_V: float, dwell_s: float, decay_s: float,
                 fn: float = FN, zeta: float = ZETA, noise: float = 0.0,
                 rng: np.random.Generator | None = None) -> pd.DataFrame:
    """A dwell from rest at `f_d` for `dwell_s`, the drive cut to zero, then `decay_s` of free decay (exact).

    Steady part + the homogeneous solution that starts the mode from rest; after the cut, the free decay from
    the state at the cut. Columns time_s, drive_V, response_accel_g (+ `noise` g rms of white noise).
    """
    t = np.arange(int(round((dwell_s + decay_s) * fs))) / fs
    wn, w = 2 * np.pi * fn, 2 * np.pi * f_d
    wd, s = wn * np.sqrt(1 - zeta**2), zeta * wn
    H = GAIN * wn**2 / (wn**2 - w**2 + 2j * zeta * wn * w)  # displacement per volt
    xs = lambda tt: level_V * (H * np.exp(1j * w * tt)).real  # noqa: E731
    vs = lambda tt: level_V * (1j * w * H * np.exp(1j * w * tt)).real  # noqa: E731

    def free(tt, x0, v0):  # free decay of the state (x0, v0) at tt = 0: displacement and acceleration
        A, B = x0, (v0 + s * x0) / wd
        x = np.exp(-s * tt) * (A * np.cos(wd * tt) + B * np.sin(wd * tt))
        v = np.exp(-s * tt) * ((-s * A + wd * B) * np.cos(wd * tt) + (-s * B - wd * A) * np.sin(wd * tt))
        return x, -2 * s * v - wn**2 * x

    on = t < dwell_s
    x0, v0 = xs(0.0), vs(0.0)
    _, a_h = free(t[on], -x0, -v0)
    acc = np.empty_like(t)
    acc[on] = level_V * (-w**2 * H * np.exp(1j * w * t[on])).real + a_h
    xc, _ = free(dwell_s, -x0, -v0)  # the state at the cut: steady + homogeneous (velocity by central difference)
    eps = 1e-7
    xp, _ = free(dwell_s + eps, -x0, -v0)
    xm, _ = free(dwell_s - eps, -x0, -v0)
    vc = (xp - xm) / (2 * eps) + vs(dwell_s)
    _, acc[~on] = free(t[~on] - dwell_s, xc + xs(dwell_s), vc)
    drive = np.where(on, level_V * np.cos(w * t), 0.0)
    rng = rng or np.random.default_rng(0)
    return pd.DataFrame({"time_s": t, "drive_V": drive,
                         "response_accel_g": acc / G + noise * rng.standard_normal(t.size)})


def kinds_campaign(folder: Path, rows: list[dict], records: dict[str, pd.DataFrame]) -> Path:
    """Write `records` (run_id -> table) as CSV and a manifest of `rows` (text cells) in `folder`."""
    folder.mkdir(parents=True, exist_ok=True)
    for rid, rec in records.items():
        rec.to_csv(folder / f"{rid}.csv", index=False, float_format="%.10g")
    pd.DataFrame(rows).to_csv(folder / "manifest.csv", index=False)
    return folder


def dwell_row(rid: str, f_d: float, seq: int, test: str = "dwell", level: float = 0.5, fs: float = 512.0) -> dict:
    """A manifest row of a voltage-driven dwell (or ring-down), sweep columns empty."""
    return {"run_id": rid, "assembly": "beam", "sequence": seq, "level_V": level, "direction": "",
            "f_start_hz": "", "f_stop_hz": "", "sweep_rate_hz_per_s": "", "sample_rate_hz": fs,
            "file": f"{rid}.csv", "test": test, "dwell_hz": f_d if test == "dwell" else ""}
