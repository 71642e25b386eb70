"""A dwell or ring-down run validated as it was done (the sweeps': `jointcal.validate.runs`).

The run is read as the modal stage read it (`jointcal.measure.testkinds.read.read_test_run`: the same frequency,
decay start, ring-down windows and dwell point), then:

* a dwell's steady point: the model driven by the dwell's record, read by the same lock-in
  (`jointcal.validate.steady.compare_dwell`);
* a decay (a ring-down, or a dwell's ring-down after the cut): the model's free decay from the record's state at
  the cut-off, read at the measured windows (`jointcal.validate.decay`).

Its metrics row carries ``test`` and the parts of E it has: E_mag and E_phase of the dwell point, E_f and E_zeta
of the decay (`jointcal.validate.error.envelope_error` pools them with the sweeps').
"""
from __future__ import annotations

import time
from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..io.contract import excitation_kind
from ..io.testkinds import DWELL, test_kind
from ..measure.dwell import dwell_point
from ..measure.testkinds.read import RECEPTANCE_COLUMNS, read_test_run, row_receptance
from ..models import MinistackModel
from .decay import compare_decay, decay_from_cut, decay_input
from .drive import model_input, reference_column, response_to
from .runs import run_head
from .steady import compare_dwell

__all__ = ["validate_test_run", "measured_read", "as_read"]


def as_read(rows: list[dict], modal: pd.DataFrame) -> list[dict]:
    """The runs' rows with how the modal stage read each: ``mode_hz`` (its ``mode_peak_hz``) and, for a decay read
    through the force, the modal constant and receptance it was read with (`RECEPTANCE_COLUMNS`), so that the
    validation and the discrepancy stage read each record as the modal stage did.

    Parameters
    ----------
    rows : list of dict
        The runs' rows of runs.csv.
    modal : DataFrame
        Their rows of modal_properties.csv (``run_id``, ``mode_peak_hz``, the receptance columns where present).
    """
    m = modal.drop_duplicates("run_id").set_index("run_id")
    cols = ["mode_peak_hz", *(c for c in RECEPTANCE_COLUMNS if c in m)] if "mode_peak_hz" in m else []
    out = []
    for r in rows:
        got = m.loc[r["run_id"], cols] if r["run_id"] in m.index else pd.Series(dtype=float)
        extra = {c: got.get(c) for c in cols[1:]}
        out.append({**r, "mode_hz": got.get("mode_peak_hz"), **extra})
    return out


def _mode_hz(row: Mapping) -> float | None:
    """The frequency the modal stage read the run at (the row's ``mode_hz``), None when it has none."""
    v = row.get("mode_hz")
    try:
        return float(v) if v is not None and np.isfinite(float(v)) else None
    except (TypeError, ValueError):
        return None


def measured_read(record: pd.DataFrame, row: Mapping) -> dict:
    """The run's record read as the modal stage read it (`jointcal.measure.testkinds.read.read_test_run` at the row's
    ``mode_hz``, through the force as measured): its dwell point, decay windows, start and flags. It does not depend
    on the model: a caller that validates many models against one record reads it once."""
    return read_test_run(row, record, excitation_kind(record.columns), _mode_hz(row), row_receptance(row))


def validate_test_run(model: MinistackModel, record: pd.DataFrame, row: Mapping, *, floor_db: float = 0.05,
                      floor_deg: float = 0.3, read: Mapping | None = None) -> tuple[pd.DataFrame, dict]:
    """One dwell or ring-down run: the model's dwell point and decay against the measured ones.

    Parameters
    ----------
    model : MinistackModel
        The run's model.
    record : DataFrame
        The measured record (time_s, its reference channel, response_accel_g; g).
    row : mapping
        Its manifest row (run_id, test, sample_rate_hz, dwell_hz for a dwell, its level column; ``mode_hz``,
        the frequency the modal stage read it at; ``drive_gain`` for a force or voltage reference).
    floor_db, floor_deg : float
        The sweeps' floors of magnitude (dB) and phase (deg) (`ValidateSettings`).
    read : mapping, optional
        The record's `measured_read` (read here when None).

    Returns
    -------
    frames : DataFrame
        The dwell point's row (``part`` 'dwell', `compare_dwell`) and the decay's windows (``part`` 'ringdown',
        `compare_decay`); empty when neither could be compared.
    metrics : dict
        One row of metrics.csv: the run's identity, ``test``, n_frames (the point and the windows compared),
        `compare_dwell`'s and `compare_decay`'s metrics, drive_scale (the decay's input scale c),
        decay_input ('reference' or 'held sine'), note (why a part was not compared), sim_s, compare_s.
    """
    t0 = time.perf_counter()
    row = dict(row)
    head = {**run_head(row), "test": test_kind(row)}
    fs = float(row["sample_rate_hz"])
    kind = excitation_kind(record.columns)
    read = measured_read(record, row) if read is None else read
    frames, metrics, notes, first = [], {}, [], None
    try:
        if read["point"] is not None:  # driven by the dwell's record (free from the decay's start, if it has one)
            x = (model_input(record, row)[0] if read["start"] is None else
                 decay_input(record, row, read["start"], read["f_guess"])[0])
            first = response_to(model, x, fs, relative=kind != "base")
            col = reference_column(record)
            sim = dwell_point(first, record[col].to_numpy(float), fs, float(row[DWELL]), kind)
            fr, mt = compare_dwell(read["point"], sim, floor_db=floor_db, floor_deg=floor_deg)
            frames.append(fr)
            metrics.update(mt)
        w = read["windows"]
        if w is not None and len(w):
            out = decay_from_cut(model, record, row, w, read["f_guess"], read["start"], first=first)
            fr, mt = compare_decay(w, out["windows"], floor_db=floor_db, floor_deg=floor_deg)
            if "through_force" in read["flags"]:  # the record decays at the rig's rate, the model at the structure's
                mt["env_end_db"] = np.nan  # their envelopes in time do not compare; f(q) and zeta(q) do
            frames.append(fr)
            metrics.update(mt, drive_scale=out["scale"], decay_input=out["source"])
            if not out["converged"]:
                notes.append(f"the model's decay did not reach the measured amplitude within {out['tries']} "
                             "simulations")
            if mt["n_windows"] < len(w):
                notes.append(f"{len(w) - mt['n_windows']} of {len(w)} windows lie outside the model's decay")
        elif read["point"] is None:
            notes.append("no steady point and no decay to read")
    except ValueError as exc:  # a record the model cannot be driven by: reported, the other runs go on
        notes.append(str(exc))
    t1 = time.perf_counter()
    n = int(metrics.get("n_windows", 0)) + (1 if "dwell_hz" in metrics else 0)
    table = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    return table, {**head, "n_frames": n, **metrics, "note": "; ".join(notes), "sim_s": t1 - t0, "compare_s": 0.0}
