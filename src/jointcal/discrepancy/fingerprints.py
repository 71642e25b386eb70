"""Where measurement and model disagree: residual maps and the fingerprint features of each effect.

Residuals are the measured transmissibility over the baseline model's (the swept fast
model, `fit.Objective.predict`), in dB and degrees, divided by the repeat scatter of
their bin. Fingerprints (each effect's test of them is its module's ``fingerprint``,
`jointcal.effects`):

==========================  ==========================================================  ==================
feature                     how                                                         points at
==========================  ==========================================================  ==================
low_gain                    median |T_meas / T_model| below 0.85 f_res                  sensor_gain
low_gain_trend              slope of ln|T_meas / T_model| against (f / f_res)^2 there   fixture_flexibility
delay_us                    -slope of the phase residual (rad) against omega off         channel_delay
                            resonance (|x| > 3), in microseconds
peak_ratio                  measured / model peak response                              (all; the paper's
                                                                                         under-prediction)
f_trend_per_decade          slope of f_res,meas / f_model - 1 against log10 level        cubic_stiffening
zeta_trend_per_decade       slope of zeta_meas / zeta_model - 1 against log10 level      quadratic_damping
drift_sigma                 slope of f_res with run sequence at the most repeated level, joint_settling
                            in repeat-scatter units over the span of the sequence
h2_ratio, h3_ratio          median 2nd / 3rd harmonic over the fundamental at the top    contact (even),
                            level                                                        cubic (odd)
masing_ratio                measured (zeta - zeta_v)/(1 - f/f0) at the lowest level      quadratic_damping
                            over its Iwan limit 4(chi+1)/(pi(chi+3))                      (> 1)
==========================  ==========================================================  ==================
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..effects import EFFECTS
from ..io import level_column
from .fit import Objective

__all__ = ["residual_map", "fingerprints", "verdicts", "outside_library", "EVEN_HARMONIC"]

EVEN_HARMONIC = 0.01  # 2nd harmonic over the fundamental at the top level above which parity counts


def residual_map(obj: Objective, theta) -> pd.DataFrame:
    """Tidy residuals of one model on its objective's runs: run_id, level, direction, sequence, f_hz, x, d_mag_db,
    d_phase_deg, z_mag, z_phase."""
    rows = []
    for i, run in enumerate(obj.runs):
        d = run.T / obj.predict(theta, i)  # measured over model
        r = run.row
        f_res = float(r["f_res_hz"])
        rows.append(pd.DataFrame(dict(
            run_id=r["run_id"], level=run.level, direction=r.get("direction", ""),
            sequence=int(r.get("sequence", 0)), f_hz=run.f_hz, f_over_fres=run.f_hz / f_res,
            d_mag_db=20 * np.log10(np.abs(d)), d_phase_deg=np.degrees(np.angle(d)),
            z_mag=20 * np.log10(np.abs(d)) / run.sigma_db, z_phase=np.degrees(np.angle(d)) / run.sigma_deg)))
    return pd.concat(rows, ignore_index=True)


def _slope(x, y) -> float:
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3 or np.ptp(x[ok]) == 0:
        return float("nan")
    return float(np.polyfit(x[ok], y[ok], 1)[0])


def fingerprints(res: pd.DataFrame, modal: pd.DataFrame, model_fz: Mapping[str, tuple[float, float]],
                 joint: Mapping[str, float], scatter_f: float, m: float) -> dict:
    """The fingerprint features of one assembly (see the module table).

    Parameters
    ----------
    res : DataFrame
        `residual_map` of the baseline.
    modal : DataFrame
        The assembly's usable modal rows (run_id, its level column, sequence, f_res_hz,
        zeta_res or zeta_phase_resonance, h2_ratio, h3_ratio).
    model_fz : mapping run_id -> (f_hz, zeta)
        The baseline's harmonic-balance frequency and damping at each run's measured amplitude.
    joint : mapping
        Baseline parameters (chi, k, KT, zeta_v).
    scatter_f : float
        Pooled relative repeat scatter of f_res.
    m : float
        Slug mass, lbf s^2/in.
    """
    out: dict[str, float] = {}
    low = res[res["f_over_fres"] < 0.85]
    out["low_gain"] = float(10 ** (low["d_mag_db"].median() / 20)) if len(low) else float("nan")
    out["low_gain_trend"] = _slope(low["f_over_fres"] ** 2, low["d_mag_db"] * np.log(10) / 20) if len(low) else np.nan
    off = res[np.abs(res["f_over_fres"] - 1) > 0.1]
    out["delay_us"] = -_slope(2 * np.pi * off["f_hz"], np.radians(off["d_phase_deg"])) * 1e6 if len(off) else np.nan
    mo = modal.copy()
    mo["f_mod"] = [model_fz[r][0] for r in mo["run_id"]]
    mo["z_mod"] = [model_fz[r][1] for r in mo["run_id"]]
    col = level_column(mo.columns)
    lev = np.log10(mo[col].astype(float))
    out["f_trend_per_decade"] = _slope(lev, mo["f_res_hz"] / mo["f_mod"] - 1)
    zc = "zeta_res" if "zeta_res" in mo else "zeta_phase_resonance"  # the read-out's damping (`data.run_zeta`)
    out["zeta_trend_per_decade"] = _slope(lev, mo[zc] / mo["z_mod"] - 1)
    counts = mo.groupby(col).size()
    lv = counts.idxmax() if len(counts) else np.nan
    rep = mo[mo[col] == lv].sort_values("sequence")
    if len(rep) >= 3 and scatter_f > 0:
        s = _slope(rep["sequence"], rep["f_res_hz"] / rep["f_res_hz"].mean())
        out["drift_sigma"] = float(s * np.ptp(rep["sequence"]) / scatter_f)
    else:
        out["drift_sigma"] = float("nan")
    top = mo[mo[col] == mo[col].max()]
    out["h2_ratio"] = float(top["h2_ratio"].median()) if "h2_ratio" in top else np.nan
    out["h3_ratio"] = float(top["h3_ratio"].median()) if "h3_ratio" in top else np.nan
    bot = mo[mo[col] == mo[col].min()]
    chi = float(joint["chi"])
    f0 = np.sqrt((joint["k"] + joint["KT"]) / m) / (2 * np.pi)
    ratio = (bot[zc] - joint["zeta_v"]) / (1 - bot["f_res_hz"] / f0)
    out["masing_ratio"] = float(ratio.median() / (4 * (chi + 1) / (np.pi * (chi + 3)))) if len(bot) else np.nan
    return {k: (float(v) if np.isfinite(v) else None) for k, v in out.items()}


def verdicts(fp: Mapping[str, float | None], sigma_db: float, sigma_f: float) -> dict[str, dict[str, list[str]]]:
    """Per registered effect: the fingerprints that agree with it ('for') and that disagree ('against').

    sigma_db : repeat scatter of the magnitude off resonance (dB); sigma_f : relative
    repeat scatter of f_res. Each effect's own test (`jointcal.effects`, its ``fingerprint``)
    says whether its feature is seen (a feature counts when it exceeds 3x its scatter); an
    effect without one has no fingerprint for or against it.
    """
    h2, h3 = fp.get("h2_ratio") or 0.0, fp.get("h3_ratio") or 0.0
    out = {}
    for name, effect in EFFECTS.items():
        if effect.fingerprint is None:
            out[name] = {"for": [], "against": []}
            continue
        hit, words = effect.fingerprint(fp, sigma_db, sigma_f)
        out[name] = {"for": [words] if hit else [], "against": [] if hit else [f"not seen: {words}"]}
    if h2 > 2 * max(h3, 1e-12):
        for name in out:
            out[name]["against"].append(f"even harmonics dominate (h2 {h2:.3f} > 2 x h3 {h3:.3f}): an asymmetric "
                                        "(contact) nonlinearity no library effect has")
    return out


def outside_library(fp: Mapping[str, float | None]) -> str | None:
    """A fingerprint no library effect can leave, in words, or None.

    Every library effect is symmetric in the joint displacement (or linear), so none puts
    a 2nd harmonic in the response. At the top level an even harmonic above
    `EVEN_HARMONIC` of the fundamental that also dominates the odd one (h2 > 2 h3; the
    Iwan joint's own harmonics are odd) means an asymmetric nonlinearity -- a contact, a
    stop, a bottoming foam cup, a rattle -- or a distorting shaker: outside the library.
    """
    h2, h3 = fp.get("h2_ratio"), fp.get("h3_ratio")
    if h2 is not None and h2 > EVEN_HARMONIC and h2 > 2 * (h3 or 0.0):
        return (f"the response's 2nd harmonic is {h2 * 100:.1f}% of the fundamental at the top level and "
                f"dominates the 3rd ({(h3 or 0.0) * 100:.2f}%): an asymmetric nonlinearity (a contact or stop that "
                "engages on one side, a bottoming foam cup) or a distorting shaker, which no library effect models")
    return None
