"""The validation envelope error E of an assembly, its repeat-scatter scale, and the misfit in words.

E is defined in `envelope_error`. Its scale is the measured repeat-to-repeat scatter
(`repeat_scatter`): what the same test gives twice is the resolution below which no
model can be judged. Where the campaign has no repeats, each run's own noise (`own_noise`).
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

__all__ = ["BINS", "repeat_scatter", "own_noise", "envelope_error", "scale_source", "scale_words", "closeness",
           "describe_misfit"]

BINS = (0.0, 1.0, 3.0, np.inf)  # |x| = |f/f_res - 1| / zeta: within half-power, flanks, far


def _offset(f: np.ndarray, f_res: float, zeta: float) -> np.ndarray:
    """x = (f/f_res - 1)/zeta: distance from resonance in half-power half-widths."""
    return (f / f_res - 1.0) / zeta


def _bin(x: np.ndarray) -> np.ndarray:
    return np.clip(np.digitize(np.abs(x), BINS[1:-1]), 0, len(BINS) - 2)


def repeat_scatter(frames: Mapping[str, pd.DataFrame], metrics: pd.DataFrame, *, floor_db: float = 0.05,
                   floor_deg: float = 0.3, n_grid: int = 200) -> pd.DataFrame:
    """Measured repeat-to-repeat scatter of the transmissibility's magnitude (dB) and phase (deg).

    Runs at the same level, direction and sweep rate (``sweep_rate_hz_per_s``, where the metrics
    carry it) with at least two usable runs form a group: the same test twice. Two sweep rates
    at one level are not repeats: near resonance they differ by their sweep transients (a set
    amplifier voltage gives both the same level; on the jointed beam's voltage rig, eta 0.5 and 2
    differ by 0.7 dB and 6.5 deg within the half-power band, against 0.05 dB and 0.3 deg of
    noise). Each
    run's measured magnitude and phase are interpolated onto a common grid of ``n_grid``
    frequencies over the band all the group's runs share; their sample standard deviation
    (ddof 1) at each grid point is binned by the distance from the group's mean
    resonance, |x| = |f/f_res - 1|/zeta in `BINS` (within the half-power band, its flanks,
    far), and pooled over groups (dof-weighted mean of variances). Each bin's scale is the
    pooled standard deviation, never less than the floor (``floor_db``, ``floor_deg``).
    A bin without repeats (most campaigns have no repeated runs) takes the runs' own noise
    there (`own_noise`: the scatter of each run's measured frames about a quadratic in
    frequency, source 'own noise'), never another bin's value: a bin's scatter says
    nothing of another's (far from resonance two sweep rates differ by their transients,
    not by noise). Without enough frames for that, the floor (source 'floor'). The floors
    (0.05 dB = 0.6%, 0.3 deg) are about what a back-to-back accelerometer pair resolves.

    Parameters
    ----------
    frames : mapping run_id -> DataFrame
        `compare_run` frames (f_hz, mag_meas_db, phase_meas_deg, in_band).
    metrics : DataFrame
        `compare_run` metrics (run_id, level, direction, f_res_meas_hz, zeta_meas).

    Returns
    -------
    DataFrame, one row per bin
        x_lo, x_hi, sigma_mag_db, sigma_phase_deg, dof, source ('repeats', 'own noise', 'floor').
    """
    ss = np.zeros((len(BINS) - 1, 2))
    dof = np.zeros(len(BINS) - 1)
    ok = metrics[metrics["n_frames"] > 0]
    rate = pd.to_numeric(ok["sweep_rate_hz_per_s"], errors="coerce") if "sweep_rate_hz_per_s" in ok else np.nan
    ok = ok.assign(_rate=rate).fillna({"_rate": -1.0})  # a run without its rate groups by level and direction
    for _, g in ok.groupby(["level", "direction", "_rate"], sort=True):
        if len(g) < 2:
            continue
        fr = [frames[r][frames[r]["in_band"]] for r in g["run_id"]]
        lo = max(d["f_hz"].min() for d in fr)
        hi = min(d["f_hz"].max() for d in fr)
        if not hi > lo:
            continue
        grid = np.linspace(lo, hi, n_grid)
        vals = []
        for d in fr:
            o = np.argsort(d["f_hz"].to_numpy())
            f = d["f_hz"].to_numpy()[o]
            vals.append([np.interp(grid, f, d[c].to_numpy()[o]) for c in ("mag_meas_db", "phase_meas_deg")])
        v = np.asarray(vals)  # (runs, 2, grid)
        v[:, 1] -= 360.0 * np.round((v[:, 1] - v[:1, 1]).mean(axis=1, keepdims=True) / 360.0)
        var = np.var(v, axis=0, ddof=1)  # (2, grid)
        b = _bin(_offset(grid, g["f_res_meas_hz"].mean(), g["zeta_meas"].mean()))
        for k in range(len(BINS) - 1):
            sel = b == k
            if sel.any():
                ss[k] += var[:, sel].mean(axis=1) * (len(g) - 1)
                dof[k] += len(g) - 1
    rows = []
    pooled = np.where(dof[:, None] > 0, np.sqrt(ss / np.maximum(dof, 1)[:, None]), np.nan)
    own, own_dof = own_noise(frames, metrics) if (dof == 0).any() else (None, None)
    for k in range(len(BINS) - 1):
        n = int(dof[k])
        if dof[k] > 0:
            s, src = pooled[k], "repeats"
        elif own is not None and own_dof[k] > 0:
            s, src, n = own[k], "own noise", int(own_dof[k])
        else:
            s, src = np.array([0.0, 0.0]), "floor"
        rows.append(dict(x_lo=BINS[k], x_hi=BINS[k + 1], sigma_mag_db=max(float(s[0]), floor_db),
                         sigma_phase_deg=max(float(s[1]), floor_deg), dof=n, source=src))
    return pd.DataFrame(rows)


def own_noise(frames: Mapping[str, pd.DataFrame], metrics: pd.DataFrame, *, degree: int = 2,
              min_frames: int = 10, chunk: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Each bin's noise of the measured magnitude (dB) and phase (deg), from the runs themselves.

    Within every run, the in-band frames of one bin on one side of the measured resonance
    (a contiguous stretch of the sweep, cut in pieces of about ``chunk`` frames) are fitted,
    piece by piece, by a polynomial of ``degree`` in f; the
    residual variance (ddof = degree + 1) is pooled over stretches and runs, weighted by
    their degrees of freedom. A shape the polynomial cannot follow adds to it (a larger
    scale, a smaller E); noise correlated over neighbouring frames (overlapping windows) is
    partly followed by it (a smaller scale, a larger E).

    Parameters
    ----------
    frames : mapping run_id -> DataFrame
        `compare_run` frames (f_hz, mag_meas_db, phase_meas_deg, in_band).
    metrics : DataFrame
        `compare_run` metrics (run_id, n_frames, f_res_meas_hz, zeta_meas).
    degree : int
        Degree of the local polynomial.
    min_frames : int
        Fewest frames a piece needs to count.
    chunk : int
        Frames per piece (a quadratic follows the response's curvature over a few frames).

    Returns
    -------
    sigma : ndarray, shape (bins, 2)
        Standard deviation of magnitude (dB) and phase (deg) per bin (NaN without dof).
    dof : ndarray of int, shape (bins,)
    """
    P = np.polynomial.polynomial
    ss = np.zeros((len(BINS) - 1, 2))
    dof = np.zeros(len(BINS) - 1, dtype=int)
    for r in metrics[metrics["n_frames"] > 0].itertuples(index=False):
        d = frames[r.run_id]
        d = d[d["in_band"]]
        f = d["f_hz"].to_numpy(float)
        x = _offset(f, r.f_res_meas_hz, r.zeta_meas)
        b = _bin(x)
        v = np.vstack([d["mag_meas_db"].to_numpy(float),
                       np.degrees(np.unwrap(np.radians(d["phase_meas_deg"].to_numpy(float))))])
        for k in range(len(BINS) - 1):
            for side in (x < 0, x >= 0):
                idx = np.flatnonzero((b == k) & side & np.all(np.isfinite(v), axis=0))
                for part in np.array_split(idx, max(1, len(idx) // chunk)):
                    if len(part) < max(min_frames, degree + 3):
                        continue
                    t = (f[part] - f[part].mean()) / max(float(np.ptp(f[part])), 1e-12)
                    ss[k] += [float(np.sum((P.polyval(t, P.polyfit(t, y[part], degree)) - y[part]) ** 2)) for y in v]
                    dof[k] += len(part) - degree - 1
    sigma = np.where(dof[:, None] > 0, np.sqrt(ss / np.maximum(dof, 1)[:, None]), np.nan)
    return sigma, dof


def envelope_error(frames: Mapping[str, pd.DataFrame], metrics: pd.DataFrame, scale: pd.DataFrame) -> dict:
    """The validation envelope error E of one assembly, and its parts.

    Definition. For every usable swept run r and every frame j of its band (drive on, neither
    record bad, full drive, f within the band around the measured resonance), let
    dM_rj = 20 log10 |T_sim / T_meas| (dB) and dP_rj = arg(T_sim / T_meas) (deg, wrapped to
    (-180, 180]), with T the transmissibility response/base of the envelopes (the
    simulation interpolated onto the measured frames' drive frequencies), and let
    sM, sP be the measured repeat-to-repeat scatter of the same quantities in the frame's
    bin of |x| = |f/f_res - 1|/zeta (`repeat_scatter`, floored). Then

        E_mag   = sqrt( mean_r mean_j (dM_rj / sM)^2 ),
        E_phase = sqrt( mean_r mean_j (dP_rj / sP)^2 ),
        E       = sqrt( (E_mag^2 + E_phase^2) / 2 ),

    each run weighted equally whatever its number of frames. A model whose envelopes
    differ from the measurement only as much as a repeated test does gives E about 1
    (a noiseless model against one noisy record: the difference has the per-run
    scatter); E grows linearly with a systematic misfit. The same means taken over the
    runs of one level give the per-level values.

    Dwells and ring-downs (metrics' ``test``; `jointcal.validate.testkinds`) bring their own parts: a dwell's
    steady point the same dM and dP over its own uncertainty (one "frame", in E_mag and E_phase); a decay the
    relative errors of f and zeta at each measured window's amplitude over the read-out's own standard errors
    (`jointcal.validate.decay.scales`), whose mean squares over the windows are the run's E_f^2 and E_zeta^2.
    A run's E^2 is the mean of the parts it has ((E_mag^2 + E_phase^2) / 2 for a sweep), and the assembly's
    E^2 the mean of its runs' (so a sweep-only campaign's E is the definition above).

    Parameters
    ----------
    frames : mapping run_id -> DataFrame
        `compare_run` frames.
    metrics : DataFrame
        `compare_run` metrics (run_id, level, n_frames, f_res_meas_hz, zeta_meas), and for dwells and
        ring-downs `validate_test_run`'s (test, E_mag, E_phase, E_f, E_zeta).
    scale : DataFrame
        `repeat_scatter`'s table.

    Returns
    -------
    dict
        E, E_mag, E_phase, n_runs, per_level {level: {E, E_mag, E_phase, n_runs}},
        scale (the bins' sigma_mag_db, sigma_phase_deg, source); with dwells or ring-downs also E_f,
        E_zeta and per_test {test: {E, ..., n_runs}} (a part no run has is None).
    """
    sm = scale["sigma_mag_db"].to_numpy()
    sp = scale["sigma_phase_deg"].to_numpy()
    tests = metrics["test"] if "test" in metrics else pd.Series("sweep", index=metrics.index)
    per_run = []
    for (_, r), test in zip(metrics.iterrows(), tests):
        if not r["n_frames"] > 0:
            continue
        if test != "sweep":
            per_run.append((r["level"], test, *(float(r.get(k, np.nan)) ** 2 for k in _PARTS)))
            continue
        d = frames[r["run_id"]]
        d = d[d["in_band"]]
        b = _bin(_offset(d["f_hz"].to_numpy(), r["f_res_meas_hz"], r["zeta_meas"]))
        per_run.append((r["level"], test, np.mean((d["d_mag_db"].to_numpy() / sm[b]) ** 2),
                        np.mean((d["d_phase_deg"].to_numpy() / sp[b]) ** 2), np.nan, np.nan))
    if not per_run:
        raise ValueError("no usable run to validate: every run is unusable or has no frame in the band.")
    t = pd.DataFrame(per_run, columns=["level", "test", "m2", "p2", "f2", "z2"])
    out = _parts(t)
    out["per_level"] = {f"{lev:g}": _parts(g) for lev, g in t.groupby("level", sort=True)}
    if set(t["test"]) != {"sweep"}:
        out["per_test"] = {k: _parts(g) for k, g in t.groupby("test", sort=True)}
    else:
        for d in (out, *out["per_level"].values()):
            d.pop("E_f"), d.pop("E_zeta")
    out["scale"] = scale.to_dict(orient="records")
    return out


_PARTS = ("E_mag", "E_phase", "E_f", "E_zeta")


def _parts(g: pd.DataFrame) -> dict:
    """E and its parts over the runs of `g` (columns m2, p2, f2, z2: each run's mean squares, NaN where absent)."""
    sq = g[["m2", "p2", "f2", "z2"]]
    part = {k: float(np.sqrt(sq[c].mean())) if sq[c].notna().any() else None for k, c in zip(_PARTS, sq.columns)}
    have = [k for k, v in part.items() if v is not None]
    if sq[[c for k, c in zip(_PARTS, sq.columns) if k in have]].notna().all().all():  # every run has every part
        e = float(np.sqrt(sum(part[k] ** 2 for k in have) / len(have)))
    else:
        e = float(np.sqrt(sq.mean(axis=1).mean()))
    return dict(E=e, **part, n_runs=int(len(g)))


def _pct(x: float) -> str:
    return f"{abs(x) * 100:.1f}%"


_SCALE = {"repeats": ("the repeat-to-repeat scatter", "a repeated test", "the repeat scatter"),
          "own noise": ("each run's own noise (no repeated runs)", "the runs' own noise", "the runs' own noise"),
          "floor": ("the noise floor validate.floor_db and floor_deg, for want of repeats or of frames enough for "
                    "the runs' own noise", "the noise floor", "the noise floor")}


def scale_source(scale: object) -> str:
    """Where E's scale came from: 'repeats' when every bin has repeats, else 'own noise' or 'floor' (the
    weakest source any bin used); ``scale`` is `repeat_scatter`'s table or its records."""
    src = set(pd.DataFrame(scale)["source"]) if scale is not None and len(scale) else {"repeats"}
    return "floor" if "floor" in src else "own noise" if "own noise" in src else "repeats"


def scale_words(source: str = "repeats") -> str:
    """What E = 1 means, for a scale source of `scale_source`."""
    return _SCALE.get(source, _SCALE["repeats"])[0]


def closeness(E: float, source: str = "repeats") -> str:
    """How close a model's envelopes are to the measured ones, in words, from E (1 = the scale of ``source``)."""
    _, test, scatter = _SCALE.get(source, _SCALE["repeats"])
    return (f"about as close as {test}" if E <= 2 and source == "repeats" else
            f"within {scatter}" if E <= 1 else f"within about twice {scatter}" if E <= 2 else
            f"clearly outside {scatter}" if E > 5 else f"somewhat outside {scatter}")


def describe_misfit(metrics: pd.DataFrame, err: Mapping, *, level_unit: str = "g") -> str:
    """The misfit in plain words: E, peak amplitude, resonance, damping, far below resonance; and where the
    runs hold dwells or ring-downs (metrics' ``test``), their steady points and decays (`_other_words`)."""
    m = metrics[metrics["n_frames"] > 0]
    if m.empty:
        return "no usable run to compare."
    src = scale_source(err.get("scale"))
    if "test" in m and (m["test"] != "sweep").any():
        swept = m[m["test"] == "sweep"]
        words = [_first_words(m, err, src, swept.empty)]
        if not swept.empty:
            words += _sweep_words(swept, level_unit)
        return " ".join(words + _other_words(m[m["test"] != "sweep"]))
    verdict = closeness(err["E"], src)
    words = [f"validation envelope error E = {err['E']:.2f} (magnitude {err['E_mag']:.2f}, phase "
             f"{err['E_phase']:.2f}; 1 = {scale_words(src)}): {verdict}."]
    return " ".join(words + _sweep_words(m, level_unit))


def _first_words(m: pd.DataFrame, err: Mapping, src: str, no_sweeps: bool) -> str:
    """E over a campaign with dwells or ring-downs: its parts and what 1 means."""
    count = ", ".join(f"{n} {k}{'s' if n > 1 else ''}" for k, n in m["test"].value_counts(sort=False).items())
    parts = [f"{name} {err[key]:.2f}" for key, name in (("E_mag", "magnitude"), ("E_phase", "phase"),
                                                         ("E_f", "frequency"), ("E_zeta", "damping"))
             if err.get(key) is not None]
    unit = ("the read-outs' own uncertainty (a dwell point's, a decay window's), never below the sweeps' floors"
            if no_sweeps else f"{scale_words(src)} for the sweeps, the read-outs' own uncertainty for the dwells "
            "and ring-downs")
    verdict = closeness(err["E"], "own noise" if no_sweeps else src)
    return (f"validation envelope error E = {err['E']:.2f} over {count} ({', '.join(parts)}; 1 = {unit}): "
            f"{verdict}.")


def _sweep_words(m: pd.DataFrame, level_unit: str) -> list[str]:
    """The sweeps' sentences after the first: peak, resonance, damping, flanks, far below resonance."""
    words = []
    pr = float(np.nanmedian(m["peak_ratio"]))
    words.append(f"The model {'under' if pr < 1 else 'over'}-predicts the peak response by {_pct(pr - 1)} "
                 f"(median over {len(m)} runs; range {m['peak_ratio'].min():.3f} to {m['peak_ratio'].max():.3f}).")
    lv = m.groupby("level")["f_res_rel_err"].median()
    same = (np.sign(lv) == np.sign(lv.median())).all()
    words.append(f"Its resonance sits {_pct(lv.median())} {'high' if lv.median() > 0 else 'low'} (median"
                 + (", same sign at every level" if same else "; the sign changes with level")
                 + "; per level " + ", ".join(f"{k:g} {level_unit}: {v * 100:+.2f}%" for k, v in lv.items()) + ").")
    zm = float(np.nanmedian(m["zeta_rel_err"]))
    words.append(f"Its damping is {_pct(zm)} {'above' if zm > 0 else 'below'} the measured (median).")
    fl = [float(m[c].dropna().median()) if m[c].notna().any() else np.nan
          for c in ("flank_below_ratio", "flank_above_ratio")]
    if np.all(np.isfinite(fl)):
        words.append(f"On the resonance's flanks (1 to 3 half-power half-widths away) the measured response is "
                     f"{_pct(1 / fl[0] - 1)} {'above' if fl[0] < 1 else 'below'} the model's below resonance and "
                     f"{_pct(1 / fl[1] - 1)} {'above' if fl[1] < 1 else 'below'} it above resonance (medians).")
    lo_ok = m["low_freq_ratio"].dropna()
    if len(lo_ok):
        lo = float(lo_ok.median())
        words.append(f"Far below resonance (f < 0.7 f_res) the measured response is {_pct(1 / lo - 1)} "
                     f"{'above' if lo < 1 else 'below'} the model's.")
    return words


def _other_words(m: pd.DataFrame) -> list[str]:
    """The dwells' steady points and the decays (ring-downs and dwells' ring-downs) in words."""
    words = []
    if "dwell_hz" in m and m["dwell_hz"].notna().any():
        d = m[m["dwell_hz"].notna()]
        r = 10 ** (d["dwell_mag_err_db"] / 20)
        med, ph = float(r.median()), float(d["dwell_phase_err_deg"].median())
        words.append(f"At the steady state of {len(d)} dwell{'s' if len(d) > 1 else ''} (the model driven by each "
                     f"dwell's record) the model's response is {_pct(med - 1)} {'above' if med > 1 else 'below'} the "
                     f"measured (median; range {r.min():.3f} to {r.max():.3f} of it) and its phase "
                     f"{abs(ph):.2f} deg {'ahead of' if ph > 0 else 'behind'} it (median).")
    if "n_windows" in m and (m["n_windows"] > 0).any():
        d = m[m["n_windows"] > 0]
        fm, zm, env = (float(d[c].median()) for c in ("f_rel_err_mean", "zeta_rel_err_mean", "env_end_db"))
        words.append(f"Along {len(d)} free decay{'s' if len(d) > 1 else ''} (read at the measured windows, from the "
                     f"measured amplitude at the cut-off, {d['q_first_meas_in'].min():.3g} to "
                     f"{d['q_first_meas_in'].max():.3g} in, over {d['decades'].min():.2f} to {d['decades'].max():.2f} "
                     f"decades) the model's frequency is {abs(fm) * 100:.3f}% {'high' if fm > 0 else 'low'} and its damping "
                     f"{_pct(zm)} {'above' if zm > 0 else 'below'} the measured at the same amplitude (medians of "
                     "the runs' mean errors)"
                     + (f"; its decay envelope ends {abs(env):.2f} dB {'above' if env > 0 else 'below'} the "
                        "measured (median)." if np.isfinite(env) else
                        "; read through the force with the shaker attached, the records decay at the rig's rate and "
                        "the model at the structure's, so their envelopes in time are not compared."))
        ref = d[d.get("decay_input", pd.Series("", index=d.index)) == "reference"]
        if len(ref):
            c = ref["drive_scale"]
            spread = "" if c.min() == c.max() else f"; range {c.min():.3g} to {c.max():.3g}"
            words.append(f"To ring down from the measured amplitude the model was driven at {c.median():.3g} times "
                         f"the recorded drive (median{spread}).")
    return words
