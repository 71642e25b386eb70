"""The modal stage on files: every run's read-outs per mode, the scatter across repeats, the FRFs and
the amplitude-dependent points, written.

Outputs (all written atomically): ``modal_properties.csv`` (one row per run and mode its band holds,
`jointcal.measure.campaign.campaign_modal`), ``scatter.csv`` (`jointcal.measure.scatter.scatter`),
``backbone.csv`` (every run's amplitude-dependent points from every test kind,
`jointcal.measure.testkinds.read.backbone_table`) and ``frf/<run_id>.csv`` (each run's whole-record FRF,
`jointcal.measure.frf.frf_table`). A run with problems gets flags and a one-sentence warning, never a
silent drop. `run_modal_unit` then cuts one (assembly, mode)'s rows out of the three tables, the files the
later stages of that unit read.
"""
from __future__ import annotations

import json
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import pandas as pd

from .._campaign_index import unit_table
from ..io import listed_record, read_run, write_csv_atomic
from .scatter import scatter

__all__ = ["run_modal", "run_modal_unit"]

_Path = str | os.PathLike[str]


def run_modal(runs_csv: _Path, envelope_files: Sequence[_Path], record_files: Sequence[_Path],
              modal: Mapping, *, table_csv: _Path, scatter_csv: _Path, backbone_csv: _Path, frf_dir: _Path,
              warn: Callable[[str], None] = lambda s: None,
              log: Callable[[str], None] = lambda s: None) -> pd.DataFrame:
    """Read every run of the campaign at each mode its band holds, and write the stage's files.

    Parameters
    ----------
    runs_csv : path
        The ingest table (``runs.csv``: one row per run, with its file and flags).
    envelope_files : sequence of paths
        The envelope stage's ``<run_id>.csv`` files; each has its ``<run_id>.json`` beside it.
    record_files : sequence of paths
        The campaign's record files, as listed by the workflow (a run's file is found by its whole
        relative path: basenames may repeat).
    modal : mapping
        The ``modal`` section of the config.
    table_csv, scatter_csv, backbone_csv : path
        Where ``modal_properties.csv``, ``scatter.csv`` and ``backbone.csv`` go.
    frf_dir : path
        The folder of per-run FRF tables (made if absent).
    warn : callable, optional
        Receives each run's problem in one sentence.
    log : callable, optional
        Receives the stage's closing line (runs, modes, rows flagged).

    Returns
    -------
    pandas.DataFrame
        ``modal_properties.csv``'s table.
    """
    # here, not at the top: `run_modal_unit` (a job per unit, splitting tables) needs none of them, and they import
    # scipy.signal and numba (about 2 s of CPU at a job's start)
    from .campaign import campaign_modal
    from .flags import run_flags
    from .frf import frf_table
    from .testkinds.read import backbone_table

    runs = pd.read_csv(runs_csv, dtype={"flags": str})
    env_dir = Path(envelope_files[0]).parent
    records = [str(r) for r in record_files]

    def load(row):
        rid = row["run_id"]
        path = listed_record(str(row["file"]), records)
        return (pd.read_csv(env_dir / f"{rid}.csv"), json.loads((env_dir / f"{rid}.json").read_text()),
                read_run(path, row) if path else None)

    points: list = []
    rows, frf, notes = campaign_modal(runs, load, modal, points=points)
    ingest_flags = dict(zip(runs["run_id"], runs["flags"]))
    for out in rows:
        out["flags"], flag_notes = run_flags(ingest_flags.get(out["run_id"]), out["flags"], out["run_id"],
                                             sweep_note=out.get("sweep_note"))
        notes += flag_notes
    Path(frf_dir).mkdir(parents=True, exist_ok=True)
    for rid, tab in frf.items():
        write_csv_atomic(frf_table(tab, rid), Path(frf_dir) / f"{rid}.csv")
    table = pd.DataFrame(rows)
    table.insert(2, "mode", table.pop("mode"))
    write_csv_atomic(table, table_csv)
    write_csv_atomic(scatter(table), scatter_csv)
    write_csv_atomic(backbone_table(table, points), backbone_csv)
    for n in notes:
        warn(n)
    log(f"modal properties of {table['run_id'].nunique()} runs at {table['mode'].nunique()} modes, "
        f"{sum(table['flags'].fillna('') != '')} rows flagged")
    return table


def run_modal_unit(table_csv: _Path, scatter_csv: _Path, backbone_csv: _Path, assembly: str, mode: str, *,
                   unit_table_csv: _Path, unit_scatter_csv: _Path, unit_backbone_csv: _Path) -> str:
    """Write one (assembly, mode)'s rows of ``modal_properties.csv``, ``scatter.csv`` and ``backbone.csv``.

    Parameters
    ----------
    table_csv, scatter_csv, backbone_csv : path
        The modal stage's three tables (`run_modal`).
    assembly, mode : str
        The unit (a mode's name as `jointcal.measure.modes.mode_name` gives it, e.g. ``m18``).
    unit_table_csv, unit_scatter_csv, unit_backbone_csv : path
        Where the unit's rows go: its runs' rows of the table (`jointcal._campaign_index.unit_table`), its
        scatter rows, and its runs' backbone points of that mode.

    Returns
    -------
    str
        The line for the log: the unit and its runs.
    """
    table = pd.read_csv(table_csv, dtype={"assembly": str, "mode": str, "flags": str})
    scatter_rows = pd.read_csv(scatter_csv, dtype={"assembly": str, "mode": str})
    rows = unit_table(table, assembly, mode)
    write_csv_atomic(rows, unit_table_csv)
    keep = scatter_rows["assembly"] == assembly
    if "mode" in scatter_rows.columns:  # (a table made before modes were tracked holds one per assembly)
        keep &= scatter_rows["mode"] == mode
    write_csv_atomic(scatter_rows[keep], unit_scatter_csv)
    backbone = pd.read_csv(backbone_csv, dtype={"run_id": str, "mode": str, "test": str})
    write_csv_atomic(backbone[backbone["run_id"].isin(rows["run_id"].astype(str)) & (backbone["mode"] == mode)],
                     unit_backbone_csv)
    return f"{assembly} {mode}: {len(rows)} runs ({', '.join(rows['run_id'])})"
