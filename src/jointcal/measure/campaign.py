"""A campaign's modal table: every run read at every mode its band holds (modal_properties.csv).

The modal stage's steps in the order data flows, on the runs of ``runs.csv``:

1. each force- or voltage-driven run's whole-record FRF gives its resonances
   (`jointcal.measure.modes.modal_peaks`);
2. per assembly, the resonances are tracked across the runs into modes, each named by its
   low-level frequency (`jointcal.measure.modes.track_modes`); ``modal.mode_hz`` restricts them;
3. each run is read at each mode its band holds (`jointcal.measure.modal.modal_properties`
   started at the run's own peak of that mode), one row per (run, mode) with the mode in the
   ``mode`` column.

A dwell or ring-down run (``test`` in runs.csv) is read by `jointcal.measure.testkinds`, after
the sweeps, named after its assembly's swept modes; its amplitude-dependent points are appended to
`points` (backbone.csv).

A base-driven run (the Ministack: one mode in its band) is read as before, at its envelope
peak (or at each ``modal.mode_hz``), and its mode is named from the read-out at the
assembly's lowest level. So is every run of an assembly in which no resonance passes the
tests of `modal_peaks`. A run whose band holds none of its assembly's modes gets one row,
flagged ``no_mode`` and unusable.

With ``modal: {coil: true}`` (off by default), a voltage drive's coil (its corner R / L and back-EMF gain:
`jointcal.measure.sweepfit`) is a constant of the rig: per assembly and mode it is fitted on the slowest
sweeps (`assembly_coil`) and held for every run, where one fast chirp barely identifies it. Off by default
because, measured on the virtual Ministack voltage rig (tests/benchmarks/accept_rigs.py), it reads the
damping closer (1.26% -> 0.90% at worst) and the frequency closer at eta 0.1-5 (+0.033 -> +0.020% at eta 0.5)
but further at eta 20 (+0.018 -> -0.036%), and a single mode's sweeps do not identify the back-EMF gain
(fitted 8-9x the rig's). Force- and base-driven runs are read without it.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from ..io.contract import LEVEL, REFERENCE, RESPONSE, UNUSABLE, excitation_kind
from ..io.testkinds import run_test_kind
from .envelopes import ENVELOPE_COLUMNS
from .frf import displacement_ratio, h1_estimate
from .modal import modal_properties
from .modes import mode_name, modal_peaks, track_modes
from .receptance import Receptance, flank_receptance
from .testkinds.read import other_kinds_modal

__all__ = ["campaign_modal", "run_peaks", "assembly_coil"]

IDENTITY = ("run_id", "assembly", "sequence", "direction")


def run_peaks(record: pd.DataFrame, row: dict, kind: str) -> np.ndarray:
    """The resonances (Hz) of one force- or voltage-driven run's whole-record FRF (`modal_peaks`)."""
    lo, hi = sorted((float(row["f_start_hz"]), float(row["f_stop_hz"])))
    if record is None or len(record) < 64:
        return np.empty(0)
    tab = h1_estimate(record[REFERENCE[kind]].to_numpy(float), record[RESPONSE].to_numpy(float),
                      float(row["sample_rate_hz"]))
    tab = tab[(tab["freq_hz"] >= lo) & (tab["freq_hz"] <= hi)]
    f = tab["freq_hz"].to_numpy()
    X = displacement_ratio(f, (tab["h1_re"] + 1j * tab["h1_im"]).to_numpy(), kind)
    return modal_peaks(f, X, tab["coherence"].to_numpy(), (lo, hi))


def _plan(rows: list[dict], records: dict, kind: str, mode_hz) -> list[tuple[dict, object, str | None]]:
    """(row, start frequency or None, mode name or None: named after reading) per read-out of one assembly."""
    given = None if mode_hz is None else [float(v) for v in np.atleast_1d(mode_hz)]
    if kind != "base":
        peaks = {r["run_id"]: run_peaks(records.get(r["run_id"]), r, kind) for r in rows}
        bands = {r["run_id"]: (float(r["f_start_hz"]), float(r["f_stop_hz"])) for r in rows}
        levels = {r["run_id"]: float(r.get(LEVEL[kind], np.nan)) for r in rows}
        tracked = track_modes(peaks, bands, levels, mode_hz=given)
        if len(tracked):
            by_run = {rid: g for rid, g in tracked.groupby("run_id", sort=False)}
            plan = []
            for r in rows:
                g = by_run.get(r["run_id"])
                if g is None:
                    plan.append((r, "none", None))
                else:
                    plan += [(r, float(t.f_guess_hz), t.mode) for t in g.itertuples()]
            return plan
    return [(r, g, None) for g in (given or [None]) for r in rows]


def campaign_modal(runs: pd.DataFrame, load: Callable[[dict], tuple], modal_kw: dict | None = None,
                   points: list | None = None):
    """Every run read at every mode its band holds.

    Parameters
    ----------
    runs : DataFrame
        ``runs.csv`` of the ingest stage (manifest rows with their flags).
    load : callable
        ``load(row) -> (env, meta, record)``: the run's envelopes (DataFrame), their metadata (dict:
        ``rate_hz_per_s``, ``window_s``, ``error``) and its raw record (DataFrame or None).
    modal_kw : dict, optional
        The config's ``modal`` section (`modal_properties`' keywords; ``mode_hz`` a number, a list or None).
    points : list, optional
        Where the dwell and ring-down runs' backbone points go (`jointcal.measure.testkinds`; rows of
        ``run_id, mode, test, q_in, f_hz, zeta``); None drops them.

    Returns
    -------
    rows : list of dict
        One row of modal_properties.csv per (run, mode), with ``mode`` (empty where a run was read at none)
        and ``mode_peak_hz`` (the frequency the read-out started at: the run's own peak of the mode, or
        ``modal.mode_hz``; NaN where it started at the envelope peak or the band's largest peak).
    frf : dict of run_id to DataFrame
        Each run's FRF (`jointcal.measure.frf.record_frf`'s table on the record's independent lines, the
        zero-padding's interpolated lines left out), one table per mode read, with a ``mode`` column.
    notes : list of str
        Sentences for the log (envelope errors).
    """
    kw = dict(modal_kw or {})
    mode_hz = kw.pop("mode_hz", None)
    with_coil = bool(kw.pop("coil", False))
    loaded, rows, frf, notes, others = {}, [], {}, [], []
    for row in runs.to_dict("records"):
        if not run_test_kind(row).swept:  # read by its kind's read-out rule (`jointcal.measure.testkinds`)
            others.append(row)
            continue
        env, meta, record = load(row)
        if meta.get("error") and record is None:
            rows.append({**{k: row.get(k) for k in IDENTITY}, "mode": "", "flags": UNUSABLE})
            notes.append(f"{row['run_id']}: {meta['error']}")
            continue
        if meta.get("error"):  # no envelopes: the whole-record FRF alone
            env = pd.DataFrame(columns=list(ENVELOPE_COLUMNS))
            notes.append(f"{row['run_id']}: {meta['error']} (the resonance comes from the whole-record FRF)")
        loaded[row["run_id"]] = (row, env, meta, record)
    sweeps = pd.DataFrame([v[0] for v in loaded.values()] or [{"assembly": None}])
    for _, group in sweeps.dropna(subset=["assembly"]).groupby("assembly", sort=False):
        grows = group.to_dict("records")
        first = loaded[grows[0]["run_id"]]
        kind = excitation_kind([*(first[3].columns if first[3] is not None else []), *first[0]])
        read = []
        plan = _plan(grows, {r: v[3] for r, v in loaded.items()}, kind, mode_hz)
        coils = assembly_coil(plan, loaded, kw, notes) if kind == "voltage" and with_coil else {}
        for row, guess, name in plan:
            _, env, meta, record = loaded[row["run_id"]]
            if guess == "none":
                rows.append({**{k: row.get(k) for k in IDENTITY}, "mode": "", "flags": "no_mode;unusable"})
                continue
            rate = meta.get("rate_hz_per_s", row["sweep_rate_hz_per_s"])
            out, tab = modal_properties(env, row, rate_hz_per_s=rate, record=record, with_frf=True,
                                        mode_hz=guess, coil=coils.get(name or guess), **kw)
            out["window_s"] = meta.get("window_s")
            out["mode_peak_hz"] = float(guess) if guess is not None else float("nan")
            read.append((out, tab, guess, name))
        _name_modes(read, kind)
        for out, tab, _, _ in read:
            rows.append(out)
            if len(tab):
                frf.setdefault(out["run_id"], []).append(_independent_lines(tab, loaded[out["run_id"]]).assign(
                    mode=out["mode"]))
    _other_kinds(others, rows, load, mode_hz, points, frf)
    order = {r: i for i, r in enumerate(runs["run_id"])}
    rows.sort(key=lambda o: order.get(o["run_id"], -1))
    return rows, {r: pd.concat(t, ignore_index=True) for r, t in frf.items()}, notes


def _other_kinds(others: list[dict], rows: list[dict], load: Callable, mode_hz, points: list | None,
                 frf: dict | None = None) -> None:
    """Append the dwell and ring-down runs' modal rows to `rows` and their backbone points to `points`.

    A force-referenced assembly's decays are read through the force (`jointcal.measure.forced_decay`) with
    each swept mode's `_receptance`."""
    for assembly, group in pd.DataFrame(others or [{"assembly": None}]).dropna(subset=["assembly"]).groupby(
            "assembly", sort=False):
        grows = group.to_dict("records")
        records = {r["run_id"]: load(r)[2] for r in grows}
        first = next((v for v in records.values() if v is not None), None)
        kind = excitation_kind([*(first.columns if first is not None else []), *grows[0]])
        mine = [r for r in rows if r.get("assembly") == assembly and UNUSABLE not in str(r.get("flags", ""))]
        swept, receptance = {}, {}
        for r in sorted(mine, key=lambda r: r.get(LEVEL[kind], np.inf)):
            if r.get("mode") and np.isfinite(r.get("f_res_hz", np.nan)):
                swept.setdefault(r["mode"], float(r["f_res_hz"]))
                if kind == "force" and r["mode"] not in receptance:
                    receptance[r["mode"]] = _receptance(r, (frf or {}).get(r["run_id"], []))
        receptance = {swept[m]: v for m, v in receptance.items() if v is not None}
        modal, pts = other_kinds_modal(grows, records, kind, swept, mode_hz, receptance=receptance)
        rows += modal
        if points is not None:
            points += pts


EDGE = 0.03  # a sweep's FRF lines within this share of its band's edges are left out (the drive's ramps)


def _receptance(row: dict, tables: list) -> Receptance | None:
    """A force-referenced mode's `Receptance` from one swept run (its lowest level's): the swept-mode fit's
    modal constant (``modal_constant_re``/``_im``) and the FRF's flanks (`flank_receptance`); None where the run
    has no fit or its FRF too few flank lines."""
    A = complex(row.get("modal_constant_re", np.nan), row.get("modal_constant_im", 0.0) or 0.0)
    tab = next((t for t in tables if (t["mode"] == row["mode"]).all()), None)
    if tab is None or not np.isfinite(A) or A == 0:
        return None
    f = tab["freq_hz"].to_numpy(float)  # the run's driven band (`jointcal.measure.frf.record_frf`)
    lo, hi = f.min(), f.max()
    inner = (f > lo + EDGE * (hi - lo)) & (f < hi - EDGE * (hi - lo))
    try:
        return flank_receptance(f[inner], (tab["x_re"] + 1j * tab["x_im"]).to_numpy()[inner], A,
                                source=str(row["run_id"]))
    except ValueError:
        return None


def assembly_coil(plan: list, loaded: dict, kw: dict, notes: list[str]) -> dict:
    """The voltage drive's coil of one assembly, per mode: fitted on its slowest sweeps, held for the rest.

    Each mode's runs within 10% of its slowest sweep rate are read with the coil fitted
    (`jointcal.measure.modal.modal_properties`, ``coil='fit'``); the coil is the median of the
    corners and back-EMF gains that earned their place, where more than half of them did (a rig's constant
    is asked for by most of its runs: on the real UNESP beam one run of six takes a corner at the range's
    edge); else the mode is read without one.

    Parameters
    ----------
    plan : list of (row, start, name)
        The assembly's read-outs (`_plan`).
    loaded : dict of run_id to (row, env, meta, record)
    kw : dict
        `modal_properties`' keywords.
    notes : list of str
        A sentence per mode read with a coil is appended.

    Returns
    -------
    dict of mode key (name, else start) to (w_e rad/s, g 1/s^2) or None
    """
    reads = {}
    for row, guess, name in plan:
        if guess != "none":
            meta = loaded[row["run_id"]][2]
            reads.setdefault(name or guess, []).append(
                (abs(float(meta.get("rate_hz_per_s", row["sweep_rate_hz_per_s"]))), row, guess))
    coils = {}
    for key, runs in reads.items():
        slowest = min(r[0] for r in runs)
        fitted, tried = [], 0
        for rate, row, guess in runs:
            _, env, _, record = loaded[row["run_id"]]
            if rate <= 1.1 * slowest and record is not None:
                tried += 1
                out = modal_properties(env, row, rate_hz_per_s=rate, record=record, mode_hz=guess, coil="fit", **kw)
                if np.isfinite(out.get("coil_w_e_rad_s", np.nan)):
                    fitted.append((row["run_id"], out["coil_w_e_rad_s"], out["coil_g_per_s2"]))
        held = 2 * len(fitted) > tried
        coils[key] = tuple(float(np.median([f[i] for f in fitted])) for i in (1, 2)) if held else None
        if held:
            notes.append(f"{runs[0][1]['assembly']} ({key}): the coil w_e {coils[key][0]:.6g} rad/s, g "
                         f"{coils[key][1]:.6g} 1/s^2 fitted on {', '.join(str(f[0]) for f in fitted)}, held for "
                         f"its {len(runs)} runs")
    return coils


def _independent_lines(tab: pd.DataFrame, loaded: tuple) -> pd.DataFrame:
    """Every line of a zero-padded FRF that is independent (spacing 1 / record length)."""
    row, record = loaded[0], loaded[3]
    df_line = tab["freq_hz"].iloc[1] - tab["freq_hz"].iloc[0]
    pad = max(1, int(round(float(row["sample_rate_hz"]) / len(record) / df_line)))
    return tab.iloc[::pad].reset_index(drop=True)


def _name_modes(read: list, kind: str) -> None:
    """Set each read-out's ``mode``: the tracked name, or (no tracking) the name of its start's
    read-outs at the lowest level; names made unique within the assembly."""
    level = LEVEL[kind]
    for key in dict.fromkeys(g for _, _, g, n in read if n is None):
        outs = [o for o, _, g, n in read if n is None and g == key]
        usable = [o for o in outs if UNUSABLE not in o["flags"] and np.isfinite(o.get("f_res_hz", np.nan))]
        low = min(usable or outs, key=lambda o: (o.get(level, np.inf), str(o["run_id"])))
        f = low.get("f_res_hz", np.nan)
        name = mode_name(f) if np.isfinite(f) else (mode_name(key) if key is not None else "m0")
        for o in outs:
            o["mode"] = name
    for o, _, _, n in read:
        if n is not None:
            o["mode"] = n
    keys = {}
    for o, _, g, n in read:  # a tracked mode is one mode whatever its runs' peaks; an untracked one, its start
        keys.setdefault(o["mode"], set()).add(n if n is not None else g)
    for name, k in keys.items():
        if len(k) > 1:  # two modes under one name (e.g. 95.2 and 95.8 Hz): the start frequency tells them apart
            for o, _, g, n in read:
                if o["mode"] == name and g is not None:
                    o["mode"] = f"{name}_{float(g):.1f}".replace(".", "p")
