"""Raw-data contract: read and validate a swept-sine campaign; write files atomically.

A campaign folder holds ``manifest.csv`` (one row per run) and one record per run
(``.csv``, ``.csv.gz`` or MATLAB ``.mat``) with the columns ``time_s`` (s),
``base_accel_g`` (g) or, for force-driven tests, ``force_lbf`` (lbf), or, for a
shaker driven open-loop, ``drive_V`` (amplifier voltage, V), and ``response_accel_g``
(g) or ``response_accel_m_s2`` (m/s^2, converted to g on read); 1 g = 386.089 in/s^2
= 9.80665 m/s^2. ``raw_data/README.md`` states the
contract for people; every violation raises `CampaignError` with one sentence that
names the file, the problem and the fix. File I/O of the package lives here (the
checks and writers are in private helper modules and re-exported).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.io
from numpy.typing import NDArray

from jointcal._atomic import write_bytes_atomic, write_csv_atomic, write_json_atomic, write_run
from jointcal._checks import validate_run
from jointcal._contract import (
    G_SI, REFERENCE, RESPONSE, RESPONSE_SI, TIME, CampaignError, CampaignWarning, OnDataProblem, excitation_of,
    fail,
)
from jointcal._manifest import check_delimiter, read_manifest

__all__ = [
    "CampaignError", "CampaignWarning", "read_manifest", "read_run", "validate_run",
    "ingest_campaign", "listed_record", "write_bytes_atomic", "write_csv_atomic", "write_json_atomic",
    "write_run",
]


def read_run(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read one run record (``.csv``, ``.csv.gz`` or MATLAB ``.mat``).

    Parameters
    ----------
    path : path-like
        CSV with the header ``time_s,base_accel_g,response_accel_g`` (force-driven:
        ``time_s,force_lbf,response_accel_g``; voltage-driven:
        ``time_s,drive_V,response_accel_g``; a response in m/s^2 is declared by naming
        its column ``response_accel_m_s2``), gzip-compressed CSV, or a MATLAB v5/v7
        file holding variables of those names as row or column vectors (other
        variables are ignored).

    Returns
    -------
    pandas.DataFrame
        Columns ``time_s`` (s), ``base_accel_g`` (g), ``force_lbf`` (lbf) or
        ``drive_V`` (V), and ``response_accel_g`` (g; converted from m/s^2 when so
        declared), all float64, shape (n, 3). Empty cells become NaN.

    Raises
    ------
    CampaignError
        Unsupported suffix, unreadable file, wrong columns, non-numeric values or
        vectors of different lengths.
    """
    path = Path(path)
    name = path.name.lower()
    if name.endswith(".mat"):
        cols = _read_mat(path)
    elif name.endswith((".csv", ".csv.gz")):
        cols = _read_csv(path)
    else:
        fail(path, "unsupported file type", "store runs as .csv, .csv.gz or .mat")
    return pd.DataFrame(cols)


def _read_csv(path: Path) -> dict[str, NDArray[np.float64]]:
    check_delimiter(path)
    try:
        df = pd.read_csv(path, skipinitialspace=True)
    except (OSError, EOFError, ValueError, UnicodeDecodeError) as exc:
        fail(path, f"cannot be read as CSV ({exc})", "re-export it as comma-separated text with one header line")
    df.columns = [str(c).strip() for c in df.columns]
    kind = excitation_of(list(df.columns), path)
    out = {}
    for col in (TIME, REFERENCE[kind], _response_name(df.columns)):
        values = pd.to_numeric(df[col], errors="coerce")
        bad = values.isna() & df[col].notna()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            fail(path, f"column '{col}' has the non-numeric value {df[col].iloc[i]!r} on line {i + 2}",
                 "export plain numbers")
        out[col] = values.to_numpy(np.float64)
    return _in_g(out)


def _response_name(names) -> str:
    """The response column present: ``response_accel_g`` or ``response_accel_m_s2``."""
    return RESPONSE_SI if RESPONSE_SI in names and RESPONSE not in names else RESPONSE


def _in_g(cols: dict[str, NDArray[np.float64]]) -> dict[str, NDArray[np.float64]]:
    """Rename a response declared in m/s^2 to ``response_accel_g``, converted to g."""
    if RESPONSE_SI in cols:
        return {(RESPONSE if k == RESPONSE_SI else k): (v / G_SI if k == RESPONSE_SI else v) for k, v in cols.items()}
    return cols


def _read_mat(path: Path) -> dict[str, NDArray[np.float64]]:
    try:
        mat = scipy.io.loadmat(path)
    except NotImplementedError:
        fail(path, "it is a MATLAB v7.3 (HDF5) file", "save it with save(..., '-v7')")
    except (OSError, ValueError, TypeError) as exc:
        fail(path, f"cannot be read as a MATLAB file ({exc})", "save it with MATLAB's save(..., '-v7')")
    names = [k for k in mat if not k.startswith("__")]
    kind = excitation_of([n for n in names if n in (TIME, RESPONSE, RESPONSE_SI, *REFERENCE.values())], path)
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
    return _in_g(out)


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
        path = campaign_dir / row["file"]
        if not path.is_file():
            fail(path, f"the file of run {row['run_id']!r} listed in manifest.csv does not exist",
                 "add the file or correct its name in the manifest's file column")
        checks = validate_run(read_run(path), row, path, on_data_problem=on_data_problem)
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
