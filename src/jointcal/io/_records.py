"""Read one run record (the contract's CSV or MAT, or a lab's export) and a whole campaign.

Private: `jointcal.io` re-exports `read_run`, `ingest_campaign` and `listed_record`.
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from jointcal.io._checks import validate_run
from jointcal.io.contract import (
    CHANNEL_COLUMNS, LEVEL, REF_FILE, REFERENCE, RESPONSE, RESPONSE_SI, START, TIME, Excitation, OnDataProblem,
    excitation_kind, excitation_of, fail,
)
from jointcal.io.testkinds import run_test_kind
from jointcal.io._lab_formats import LAB_SUFFIXES, is_testlab, read_lab_export
from jointcal.io._manifest import check_csv_text, read_manifest
from jointcal.units import G_SI

__all__ = ["read_run", "ingest_campaign", "listed_record"]


def read_run(path: str | os.PathLike[str], row: Mapping[str, Any] | None = None) -> pd.DataFrame:
    """Read one run record: the contract's CSV or MAT file, or a lab's own export.

    Parameters
    ----------
    path : path-like
        CSV with the header ``time_s,base_accel_g,response_accel_g`` (force-driven:
        ``time_s,force_lbf,response_accel_g``; voltage-driven:
        ``time_s,drive_V,response_accel_g``; a response in m/s^2 is declared by naming
        its column ``response_accel_m_s2``), gzip-compressed CSV, or a MATLAB v5/v7
        file holding variables of those names as row or column vectors (other
        variables are ignored); or a lab's export (`jointcal.io._lab_formats`): UFF 58
        (``.uff``, ``.unv``), NI TDMS (``.tdms``) or a Simcenter Test.Lab MATLAB export
        (``.mat`` holding structs with ``x_values`` and ``y_values``).
    row : mapping, optional
        The run's manifest row (`read_manifest`; a row of runs.csv will do). Its level
        column gives the excitation; its ``sweep_start_s`` (s) drops the samples before
        the sweep; its ``reference_channel`` and ``response_channel`` name a lab
        export's channels (required for those formats), its ``reference_file`` the lab
        export holding the reference when the lab exported it apart (relative to the
        manifest's folder); a ``ringdown`` whose drive was not recorded leaves
        ``reference_channel`` empty (its reference column is then zero).

    Returns
    -------
    pandas.DataFrame
        Columns ``time_s`` (s), ``base_accel_g`` (g), ``force_lbf`` (lbf) or
        ``drive_V`` (V), and ``response_accel_g`` (g; converted from m/s^2 when so
        declared, or from the unit a lab export gives), all float64, shape (n, 3).
        Empty cells become NaN. ``attrs['sources']`` maps each column to the file's
        name for it, its declared unit and how it was declared ('name', 'file' or
        'none'); ``attrs['format']`` names the format.

    Raises
    ------
    CampaignError
        Unsupported suffix, unreadable file, wrong columns, non-numeric values,
        vectors of different lengths, a lab export's channel that is not named or not
        in the file, or a unit that is not the quantity of the channel's role.
    """
    path = Path(path)
    name = path.name.lower()
    kind = _row_excitation(row)
    channels = {role: _cell(row, col) for role, col in CHANNEL_COLUMNS.items()} if row is not None else {}
    lab = {"reference_path": _reference_path(path, row), "no_reference": row is not None and run_test_kind(row).reference_optional}
    if name.endswith(".mat"):
        cols, attrs = _read_mat(path, kind, channels, row, lab)
    elif name.endswith((".csv", ".csv.gz")):
        cols, attrs = _read_csv(path, kind)
    elif name.endswith(LAB_SUFFIXES):
        cols, attrs = read_lab_export(path, kind, channels, _cell(row, "run_id"), **lab)
    else:
        fail(path, "unsupported file type",
             f"store runs as .csv, .csv.gz or .mat, or as a lab export ({', '.join(LAB_SUFFIXES)})")
    if lab["reference_path"] and attrs["format"] in ("CSV", "MAT"):
        fail(path, f"the manifest names a reference_file ({_cell(row, REF_FILE)}) for a {attrs['format']} record, "
             "which holds its reference itself", "leave reference_file empty for this run")
    if any(channels.values()) and attrs["format"] in ("CSV", "MAT"):
        fail(path, f"the manifest names channels ({', '.join(c for c in channels.values() if c)}) for a "
             f"{attrs['format']} record, whose {'column' if attrs['format'] == 'CSV' else 'variable'} names are "
             "the contract's", "leave reference_channel and response_channel empty for this run")
    df = pd.DataFrame(cols)
    df.attrs.update(attrs)
    return _from_sweep_start(df, row, path)


def _cell(row: Mapping[str, Any] | None, col: str) -> str | None:
    """A text cell of a manifest row, None when absent or empty (NaN in a runs.csv read back)."""
    value = None if row is None else row.get(col)
    if isinstance(value, float) and value.is_integer():  # a numeric name read back from runs.csv
        value = str(int(value))
    return None if value is None or (isinstance(value, float) and np.isnan(value)) or not str(value).strip() \
        else str(value).strip()


def _reference_path(path: Path, row: Mapping[str, Any] | None) -> Path | None:
    """The file the row's ``reference_file`` names (relative to the manifest's folder, as ``file``), or None."""
    ref, file = _cell(row, REF_FILE), _cell(row, "file")
    if ref is None:
        return None
    folder = path.parents[len(Path(file).parts) - 1] if file and str(path).endswith(Path(file).name) else path.parent
    ref_path = folder / ref
    if not ref_path.is_file():
        fail(ref_path, f"the reference_file of run {_cell(row, 'run_id')!r} listed in manifest.csv does not exist",
             "add the file or correct its name in the manifest's reference_file column")
    return ref_path


def _row_excitation(row: Mapping[str, Any] | None) -> Excitation | None:
    """The excitation the row's (non-empty) level column gives, None without a row or level."""
    return None if row is None else excitation_kind([c for c in LEVEL.values() if _cell(row, c) is not None], None)


def _from_sweep_start(df: pd.DataFrame, row: Mapping[str, Any] | None, path: Path) -> pd.DataFrame:
    """Drop the samples before the row's ``sweep_start_s`` (a pre-trigger head)."""
    start = float(_cell(row, START) or 0.0)
    if start <= 0:
        return df
    i0 = int(round(start * float(row["sample_rate_hz"])))
    if i0 > len(df) - 16:
        fail(path, f"{START} = {start:g} s is past the record's end ({len(df)} samples)",
             f"give the sweep's start in seconds after the record's first sample in {START}")
    out = df.iloc[i0:].reset_index(drop=True)
    out.attrs.update(df.attrs)
    return out


def _read_csv(path: Path, kind: Excitation | None) -> tuple[dict[str, NDArray[np.float64]], dict[str, Any]]:
    check_csv_text(path)
    try:
        df = pd.read_csv(path, skipinitialspace=True)
    except (OSError, EOFError, ValueError, UnicodeDecodeError) as exc:
        fail(path, f"cannot be read as CSV ({exc})", "re-export it as comma-separated text with one header line")
    df.columns = [str(c).strip() for c in df.columns]
    kind = excitation_of(list(df.columns), path, expected=kind)
    out = {}
    for col in (TIME, REFERENCE[kind], _response_name(df.columns)):
        values = pd.to_numeric(df[col], errors="coerce")
        bad = values.isna() & df[col].notna()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            fail(path, f"column '{col}' has the non-numeric value {df[col].iloc[i]!r} on line {i + 2}",
                 "export plain numbers")
        out[col] = values.to_numpy(np.float64)
    return _in_g(out, "CSV")


def _response_name(names) -> str:
    """The response column present: ``response_accel_g`` or ``response_accel_m_s2``."""
    return RESPONSE_SI if RESPONSE_SI in names and RESPONSE not in names else RESPONSE


def _in_g(cols: dict[str, NDArray[np.float64]], fmt: str) -> tuple[dict[str, NDArray[np.float64]], dict[str, Any]]:
    """Rename a response declared in m/s^2 to ``response_accel_g``, converted to g; the sources (see `read_run`)."""
    units = {TIME: "s", RESPONSE: "g", RESPONSE_SI: "m/s^2", REFERENCE["base"]: "g", REFERENCE["force"]: "lbf",
             REFERENCE["voltage"]: "V"}
    noun = "column" if fmt == "CSV" else "variable"
    sources = {(RESPONSE if k == RESPONSE_SI else k): {"name": k, "unit": units[k], "by": "name", "noun": noun}
               for k in cols}
    if RESPONSE_SI in cols:
        cols = {(RESPONSE if k == RESPONSE_SI else k): (v / G_SI if k == RESPONSE_SI else v) for k, v in cols.items()}
    return cols, {"format": fmt, "sources": sources}


def _read_mat(path: Path, kind: Excitation | None, channels: dict[str, str | None],
              row: Mapping[str, Any] | None, lab: dict) -> tuple[dict[str, NDArray[np.float64]], dict[str, Any]]:
    import scipy.io  # here: the workflow imports jointcal.io to name its jobs, every Snakemake run and stage

    try:
        mat = scipy.io.loadmat(path)
    except NotImplementedError:
        fail(path, "it is a MATLAB v7.3 (HDF5) file", "save it with save(..., '-v7')")
    except OSError as exc:  # scipy.io: 'could not read bytes', the file ends inside a variable
        fail(path, f"it ends before its data do ({exc}): the file is cut short",
             "export the run again (or copy the whole file)")
    except (ValueError, TypeError) as exc:
        fail(path, f"cannot be read as a MATLAB file ({exc})", "save it with MATLAB's save(..., '-v7')")
    names = [k for k in mat if not k.startswith("__")]
    if is_testlab(mat):
        return read_lab_export(path, kind, channels, _cell(row, "run_id"), **lab)
    kind = excitation_of(names, path, expected=kind, noun="variable", others_ok=True)
    out = {}
    for var in (TIME, REFERENCE[kind], _response_name(names)):
        a = np.asarray(mat[var])
        if a.ndim > 2 or (a.ndim == 2 and min(a.shape) != 1) or not np.issubdtype(a.dtype, np.number):
            fail(path, f"variable '{var}' is a {a.dtype} array of shape {a.shape}, not a numeric vector",
                 "save each channel as a row or column vector")
        out[var] = a.ravel().astype(np.float64)
    lengths = {len(v) for v in out.values()}
    if len(lengths) != 1:
        fail(path, f"variables have different lengths {sorted(lengths)}", "save the three channels with one length")
    return _in_g(out, "MAT")


def ingest_campaign(campaign_dir: str | os.PathLike[str], *,
                    on_data_problem: OnDataProblem = "error") -> pd.DataFrame:
    """Read and validate a whole campaign folder.

    Parameters
    ----------
    campaign_dir : path-like
        Folder holding ``manifest.csv`` and the run files it lists.
    on_data_problem : {'error', 'flag'}, optional
        Passed to `validate_run`.

    Returns
    -------
    pandas.DataFrame
        One row per run in manifest order: the manifest's columns, then the checks
        of `validate_run`, with ``flags`` joined by ';' (empty string when clean).

    Raises
    ------
    CampaignError
        The first contract violation found, including a run file that is missing.
    """
    campaign_dir = Path(campaign_dir)
    manifest = read_manifest(campaign_dir / "manifest.csv")
    rows = []
    for _, row in manifest.iterrows():
        path = campaign_dir / row["file"]  # read_manifest checked that it exists
        checks = validate_run(read_run(path, row), row, path, on_data_problem=on_data_problem)
        checks["flags"] = ";".join(checks["flags"])
        rows.append({**row.to_dict(), **checks})
    return pd.DataFrame(rows)


def listed_record(file: str | os.PathLike[str], paths: list[str] | tuple[str, ...]) -> str | None:
    """The path among `paths` that is the manifest's run `file`, matched on its whole relative path.

    Parameters
    ----------
    file : path-like
        The manifest's ``file`` cell (relative to the campaign folder).
    paths : sequence of str
        Paths of the campaign's run files (the campaign folder joined with each ``file``).

    Returns
    -------
    str or None
        The shortest path ending with all of `file`'s parts (``a/run.csv`` is not
        ``b/a/run.csv``); None if none does. Never matched on the basename alone:
        two folders may hold files of one name.
    """
    parts = Path(file).parts
    hits = [p for p in paths if Path(p).parts[-len(parts):] == parts]
    return min(hits, key=lambda p: len(Path(p).parts)) if hits else None
