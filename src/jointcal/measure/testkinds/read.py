"""The runs of the test kinds that are not swept read from their records, and backbone.csv.

A sweep run is read by `jointcal.measure.campaign` as before and gives one point, its read-out.
The runs of the other test kinds (`jointcal.io.testkinds`), in the order data flows:

1. **The mode's frequency**: the largest peak of the response's spectrum over its free decay
   (a ring-down, or a dwell's ring-down after the cut), else the dwell's frequency; the nearest of
   ``modal.mode_hz`` when given. Runs are named after the assembly's swept mode within `NEAR` of
   it, else grouped (frequencies within `NEAR`) and named by the lowest level's read-out (its
   largest ring-down window's frequency, else its spectral peak; `jointcal.measure.modes.mode_name`).
2. **Ring-down windows** (`jointcal.measure.ringdown.ringdown_backbone`): a ring-down, and a dwell
   whose record goes on for at least `MIN_DECAY_S` after its drive is cut, give one point per window.
   A force reference that stays live after the cut (`LIVE`: the shaker left attached) rings at the
   coupled rig's pole: read through the force (`jointcal.measure.forced_decay`) with the modal
   constant and residual receptance the assembly's lowest-level sweep of that mode measured
   (``through_force``), or not read where no sweep measured them (``shaker_on``).
3. **Dwell points** (`jointcal.measure.dwell`): each dwell's steady point; a level's dwells (three
   or more per assembly, mode and level) give the modal constant and so each dwell's natural
   frequency and damping at the amplitude it reached, and the level's phase resonance. Force-referenced,
   where the mode's sweep measured its modal constant and the other modes' receptance R
   (`jointcal.measure.receptance`), each dwell's X - R is read with that constant, however few dwells
   a level holds: an open-loop rig's manifest level is the force each dwell measured, one per dwell.
4. **The run's row**: its kind's read-out rule (`jointcal.measure.testkinds.registry.READOUT_RULES`),
   the first of its estimators that reads it (a ring-down's largest-amplitude window, a dwell's point),
   ``f_res_method`` naming it, so the later stages read it like a sweep's; ``unusable`` where all refuse.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...io.contract import LEVEL, REFERENCE, RESPONSE, UNUSABLE
from ...io.testkinds import DEFAULT, DWELL, run_test_kind
from ...spectral import peak_frequency
from ...units import G
from ..dwell import dwell_mode, dwell_point
from ..forced_decay import forced_decay_backbone
from ..modes import mode_name
from ..receptance import Receptance
from ..ringdown import decay_start, ringdown_backbone
from .registry import READOUT_RULES, methods
from .ringdown import METHOD as WINDOWS, MIN_DECAY_S, SE_COLUMNS

__all__ = ["other_kinds_modal", "backbone_table", "read_test_run", "receptance_row", "row_receptance",
           "BACKBONE_COLUMNS", "RECEPTANCE_COLUMNS", "MIN_DECAY_S", "NEAR"]

BACKBONE_COLUMNS = ["run_id", "mode", "test", "q_in", "f_hz", "zeta"]
LIVE = 0.1  # a force reference above this share of its level before the cut over the decay: the shaker stays on
NEAR = 0.1  # relative distance within which two frequencies are one mode
IDENTITY = ("run_id", "assembly", "sequence", "direction")


def _peak_hz(x: np.ndarray, fs: float, lo: float = 0.5, decay: bool = False) -> float:
    """The largest spectral peak of `x` above `lo` Hz (`jointcal.spectral.peak_frequency`, 8x zero padding).

    A decay is cut where it last stands 20x over its tail's median (the noise) and read without a
    window (it tapers itself); any other record under a Hann window.
    """
    if decay:
        a = np.abs(x - np.median(x))
        noise = np.median(a[-max(a.size // 10, 1):])
        x = x[:max(int(np.flatnonzero(a > 20 * noise)[-1]) + 1 if (a > 20 * noise).any() else a.size, 64)]
    return peak_frequency(x, fs, pad=8, window=not decay, lo=lo)


def _live_after_cut(ref: np.ndarray, start: int, fs: float) -> float:
    """The reference's rms over the decay's first `MIN_DECAY_S` over its rms over the drive's last second."""
    x = ref - np.median(ref)
    n = int(MIN_DECAY_S * fs)
    before, after = x[max(start - n, 0):start], x[start:start + n]
    rms = lambda v: float(np.sqrt(np.mean(v**2))) if v.size else 0.0  # noqa: E731
    return rms(after) / rms(before) if rms(before) > 0 else 0.0


def _decay(resp: np.ndarray, ref: np.ndarray, fs: float) -> int | None:
    """The decay's start (from the drive when it holds one, else from the response), None without one."""
    live = np.abs(ref - np.median(ref)).max() > 0
    try:
        start = decay_start(fs, resp, ref - np.median(ref) if live else None)
    except ValueError:
        return None
    return start if (resp.size - start) / fs >= MIN_DECAY_S else None


def read_test_run(row: dict, record: pd.DataFrame, kind: str, mode_hz=None, receptance: dict | None = None) -> dict:
    """One dwell or ring-down run read as the modal stage reads it (steps 1-3 of the module docstring).

    Parameters
    ----------
    row : dict
        Its row of runs.csv (``test``, ``sample_rate_hz``, ``dwell_hz`` for a dwell).
    record : DataFrame
        Its record (`jointcal.io.read_run`).
    kind : {'base', 'force', 'voltage'}
        The excitation.
    mode_hz : float or list of float, optional
        The frequencies to read at (``modal.mode_hz``, or the modal stage's own read: its ``mode_peak_hz``).
    receptance : dict of float to Receptance, optional
        Force-referenced: each swept mode's frequency (Hz) and what the campaign's sweeps measured of it
        (`jointcal.measure.forced_decay.Receptance`). A decay that the shaker still pushes on (``shaker_on``)
        is read through the force with the mode's within `NEAR` (flag ``through_force``); without one it
        is not read.

    Returns
    -------
    dict
        ``row``; ``f_guess`` (Hz), the frequency read at; ``start``, the decay's first sample (None without a
        decay of `MIN_DECAY_S`); ``windows`` (`ringdown_backbone`'s table, None without a decay); ``point``
        (`dwell_point`'s dict, None but for a dwell); ``notes``.
    """
    fs = float(row["sample_rate_hz"])
    resp = np.nan_to_num(record[RESPONSE].to_numpy(float))
    ref = np.nan_to_num(record[REFERENCE[kind]].to_numpy(float))
    start = _decay(resp, ref, fs)
    if start is not None:
        f = _peak_hz(resp[start:], fs, decay=True)
    elif DWELL in run_test_kind(row).needs:  # a dwell: its drive's frequency
        f = float(row[DWELL])
    else:
        f = _peak_hz(resp, fs)
    if mode_hz is not None:
        f = min((float(v) for v in np.atleast_1d(mode_hz)), key=lambda v: abs(v - f))
    out = {"row": row, "f_guess": f, "start": start, "windows": None, "point": None, "notes": [], "flags": []}
    if start is not None and kind == "force" and _live_after_cut(ref, start, fs) > LIVE:
        near = [(abs(fm / f - 1), fm) for fm in (receptance or {}) if abs(fm / f - 1) < NEAR]
        if near:  # the decay is the structure's and the shaker's together: read the structure's through the force
            rc = receptance[min(near)[1]]
            out["windows"] = forced_decay_backbone(resp, ref, fs, f, rc.modal_constant, residual=rc.residual(f),
                                                   start=start)
            out["flags"].append("through_force")
            out["receptance"] = rc
        else:
            out["flags"].append("shaker_on")  # no modal constant measured: not read
    elif start is not None:
        out["windows"] = ringdown_backbone(resp, fs, f, start=start)
    if DWELL in run_test_kind(row).needs:
        out["point"] = dwell_point(resp, ref, fs, float(row[DWELL]), kind)
    return out


def _names(reads: list[dict], swept: dict[str, float], level: str) -> None:
    """Each read-out's mode: the swept mode within NEAR, else its group's name at the lowest level."""
    for r in reads:
        near = [(abs(f / r["f_guess"] - 1), m) for m, f in swept.items() if abs(f / r["f_guess"] - 1) < NEAR]
        r["mode"] = min(near)[1] if near else None
    rest = sorted((r for r in reads if r["mode"] is None), key=lambda r: r["f_guess"])
    groups: list[list[dict]] = []
    for r in rest:
        if groups and r["f_guess"] / groups[-1][-1]["f_guess"] - 1 < NEAR:
            groups[-1].append(r)
        else:
            groups.append([r])
    for g in groups:
        low = min(g, key=lambda r: (float(r["row"].get(level, np.inf)), str(r["row"]["run_id"])))
        w = low["windows"]  # named by its read-out, as a sweep's mode: the largest window's frequency
        f = float(w.loc[w["q_in"].idxmax(), "f_hz"]) if w is not None and len(w) else low["f_guess"]
        for r in g:
            r["mode"] = mode_name(f)


def other_kinds_modal(rows: list[dict], records: dict, kind: str, swept: dict[str, float],
                      mode_hz=None, *, receptance: dict | None = None) -> tuple[list[dict], list[dict]]:
    """The modal rows and backbone points of one assembly's dwell and ring-down runs.

    Parameters
    ----------
    rows : list of dict
        The runs' rows of runs.csv (``test`` ``dwell`` or ``ringdown``).
    records : dict of run_id to DataFrame
        Their records (`jointcal.io.read_run`).
    kind : {'base', 'force', 'voltage'}
        The assembly's excitation.
    swept : dict of str to float
        The assembly's swept modes: name -> frequency (Hz) at their lowest level.
    mode_hz : float or list of float, optional
        The config's ``modal.mode_hz``.
    receptance : dict of float to Receptance, optional
        Force-referenced: per swept mode's frequency (Hz), its modal constant and residual receptance from the
        campaign's sweeps (`read_test_run`).

    Returns
    -------
    modal : list of dict
        One modal_properties.csv row per run.
    points : list of dict
        `BACKBONE_COLUMNS` rows: each ring-down window (``test`` ``ringdown``) and each dwell's point.
    """
    level = LEVEL[kind]
    reads = [read_test_run(r, records[r["run_id"]], kind, mode_hz, receptance) for r in rows
             if records.get(r["run_id"]) is not None]
    _names(reads, swept, level)
    dwells: dict[tuple, list[dict]] = {}
    for r in reads:
        if r["point"] is not None:
            dwells.setdefault((r["mode"], float(r["row"][level])), []).append(r)
    for (mode, _), group in dwells.items():
        pts = [r["point"] for r in group]
        rc = (receptance or {}).get(swept.get(mode)) if kind == "force" else None
        if len(pts) < 3 and rc is None:  # no modal constant: the points' frequencies and damping cannot be read
            nan = float("nan")
            for r in group:
                r["dwell"] = {"q_in": r["point"]["q_in"], "f_hz": nan, "zeta": nan,
                              "fit": {"f_hz": nan, "zeta": nan, "q_in": nan, "residual": nan, "flags": ["few_dwells"]}}
            continue
        f = np.array([p["f_hz"] for p in pts])
        X, q, A = np.array([p["X"] for p in pts]), np.array([p["q_in"] for p in pts]), -G if kind == "base" else None
        if rc is not None:  # the mode's modal constant and the other modes' receptance, measured by its sweep
            X = X - np.array([rc.residual(v) for v in f])
            q, A = np.abs(X) * np.array([p["ref_amp"] for p in pts]), rc.modal_constant
        fit = dwell_mode(f, X, q, A=A)
        if rc is not None and len(pts) == 1:  # A measured: nothing fitted, the one point is its own read-out
            fit["flags"] = []
        for r, (qi, fi, zi) in zip(group, fit["points"]):
            r["dwell"] = {"q_in": qi, "f_hz": fi, "zeta": zi, "fit": fit}
    modal, points = [], []
    for r in reads:
        row, rid = r["row"], r["row"]["run_id"]
        w = r["windows"]
        if w is not None and len(w):
            se = {c: w[c] for c in SE_COLUMNS if c in w}  # each window's length and own standard errors
            points += [{"run_id": rid, "mode": r["mode"], "test": WINDOWS, "q_in": q, "f_hz": f, "zeta": z,
                        **{c: float(v.iloc[i]) for c, v in se.items()}}
                       for i, (q, f, z) in enumerate(zip(w["q_in"], w["f_hz"], w["zeta"]))]
        out = {**{k: row.get(k) for k in IDENTITY}, level: row.get(level), "mode": r["mode"],
               "test": row.get("test"), "mode_peak_hz": r["f_guess"]}
        _, readout, flags, pts = READOUT_RULES[run_test_kind(row).name].read(r)
        out.update(readout)
        points += pts
        if r.get("receptance") is not None:  # what the decay was read through: the later stages read it alike
            out.update(receptance_row(r["receptance"]))
        if w is not None and len(w):
            out["ringdown_windows"] = len(w)
            out["ringdown_decades"] = float(np.log10(w["q_in"].max() / w["q_in"].min()))
        out.update(zeta_phase_resonance=out.get("zeta_res"), zeta_half_power=out.get("zeta_res"),
                   flags=";".join(dict.fromkeys(flags)))
        modal.append(out)
    return modal, points


RECEPTANCE_COLUMNS = ("through_force_A_re", "through_force_A_im", "through_force_r0", "through_force_r2")


def receptance_row(rc: Receptance) -> dict:
    """The modal row's columns (`RECEPTANCE_COLUMNS`) of the `Receptance` a decay was read through the force with."""
    return dict(zip(RECEPTANCE_COLUMNS, (rc.modal_constant.real, rc.modal_constant.imag, rc.r0, rc.r2)))


def row_receptance(row) -> dict | None:
    """The ``receptance`` argument of `read_test_run` from a modal row's `RECEPTANCE_COLUMNS` (keyed by its
    ``mode_hz``, the frequency it was read at), or None where the run was not read through the force."""
    vals = [row.get(c) for c in RECEPTANCE_COLUMNS]
    f = row.get("mode_hz")
    try:
        vals, f = [float(v) for v in vals], float(f)
    except (TypeError, ValueError):
        return None
    if not np.all(np.isfinite([*vals, f])):
        return None
    return {f: Receptance(complex(vals[0], vals[1]), vals[2], vals[3], source=str(row.get("run_id", "")))}


def backbone_table(modal: pd.DataFrame, points: list[dict]) -> pd.DataFrame:
    """backbone.csv: every sweep row's read-out (``q_in``, ``f_res_hz``, ``zeta_res``) and the other kinds' points.

    The rows flagged ``unusable`` are left out; the order is the modal table's runs, windows in time order. Where
    any point carries its length and standard errors (a ring-down's windows: ``window_s``, ``f_se_hz``,
    ``zeta_se``, `jointcal.measure.testkinds.ringdown.SE_COLUMNS`) the table has those columns too, empty for the other rows (a
    campaign of sweeps keeps its six).
    """
    usable = ~modal["flags"].fillna("").str.contains(UNUSABLE)
    method = modal["f_res_method"] if "f_res_method" in modal else pd.Series("", index=modal.index)
    sweep = ~method.isin(methods())
    rows = modal.loc[usable & sweep].reindex(columns=["run_id", "mode", "q_in", "f_res_hz", "zeta_res"])
    out = [pd.DataFrame({"run_id": rows["run_id"], "mode": rows["mode"], "test": DEFAULT, "q_in": rows["q_in"],
                         "f_hz": rows["f_res_hz"], "zeta": rows["zeta_res"]})]
    bad = set(modal.loc[~usable, "run_id"])
    se = [c for c in SE_COLUMNS if any(c in p for p in points)]  # windows' lengths and errors, where read
    out.append(pd.DataFrame([p for p in points if p["run_id"] not in bad], columns=BACKBONE_COLUMNS + se))
    table = pd.concat(out, ignore_index=True)
    order = {r: i for i, r in enumerate(dict.fromkeys(modal["run_id"]))}
    key = table["run_id"].map(order)
    return table.iloc[np.argsort(key.to_numpy(), kind="stable")].reset_index(drop=True)
