"""Atomic file writers and the run-record writer (re-exported by `jointcal.io`).

Every writer writes a temporary file in the target's folder and then `os.replace`s it
into place, so an interrupted run never leaves a half-written file.
"""
from __future__ import annotations

import gzip
import io
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from jointcal.io.contract import REFERENCE, RESPONSE, TIME, Excitation

__all__ = ["write_bytes_atomic", "write_csv_atomic", "write_json_atomic", "write_run"]


def _write_atomic(path: str | os.PathLike[str], write: Callable[[IO[bytes]], object]) -> Path:
    """Call ``write(fh)`` on a temporary file beside `path`, then `os.replace` it into place.

    On any exception the temporary file is removed and an existing `path` is untouched.
    The new file gets the usual permissions (0o666 less the umask), not mkstemp's 0o600.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        umask = os.umask(0o022)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _text(write: Callable[[IO[str]], object]) -> Callable[[IO[bytes]], None]:
    """Adapt a text writer to the binary file of `_write_atomic` (UTF-8, newlines as written)."""
    def inner(fh: IO[bytes]) -> None:
        text = io.TextIOWrapper(fh, encoding="utf-8", newline="")
        try:
            write(text)
        finally:
            text.detach()  # flushes; leaves `fh` to its owner
    return inner


def write_bytes_atomic(data: bytes, path: str | os.PathLike[str]) -> Path:
    """Write bytes to a file atomically.

    Parameters
    ----------
    data : bytes
        The whole content.
    path : path-like
        Target file; missing parent folders are created. It is replaced only once the
        new content is completely on disk, so an interrupted run leaves either the old
        file or the new one, never half a file (nor a stray temporary file).

    Returns
    -------
    pathlib.Path
        The written file.
    """
    return _write_atomic(path, lambda fh: fh.write(data))


def write_csv_atomic(df: pd.DataFrame, path: str | os.PathLike[str]) -> Path:
    """Write a table as CSV atomically (see `write_bytes_atomic`).

    Parameters
    ----------
    df : pandas.DataFrame
        The table; written without its index, UTF-8, ``\n`` line ends, full float
        precision (missing values as empty cells).
    path : path-like
        Target file; missing parent folders are created.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    return _write_atomic(path, _text(lambda fh: df.to_csv(fh, index=False, lineterminator="\n")))


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic | np.ndarray):
        return obj.tolist()
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    raise TypeError(f"Object of type {type(obj).__name__} is not JSON serializable")


def write_json_atomic(obj: Any, path: str | os.PathLike[str], *, indent: int = 2) -> Path:
    """Write an object as JSON atomically (see `write_bytes_atomic`).

    Parameters
    ----------
    obj : object
        JSON-serialisable data; numpy scalars and arrays (as lists) and paths (as
        strings) are accepted too. NaN is written as ``NaN``.
    path : path-like
        Target file; missing parent folders are created.
    indent : int, optional
        Indentation of the JSON text (spaces).

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    TypeError
        For an object JSON cannot represent; `path` is then left as it was.
    """
    def dump(fh: IO[str]) -> None:
        json.dump(obj, fh, indent=indent, default=_json_default, allow_nan=True)
        fh.write("\n")
    return _write_atomic(path, _text(dump))


def _csv_bytes(cols: dict[str, np.ndarray]) -> bytes:
    """The columns as CSV: a header of their names, then one ``%.9g`` line per sample. The bytes
    ``np.savetxt(fmt="%.9g", delimiter=",", header=..., comments="")`` writes, formatted from Python floats in
    one pass (savetxt formats and writes line by line: two fifths of a record's text time)."""
    line = ",".join(["%.9g"] * len(cols)) + "\n"
    rows = np.column_stack(list(cols.values())).tolist()
    return (",".join(cols) + "\n" + "".join([line % tuple(r) for r in rows])).encode("latin1")


def write_run(path: str | os.PathLike[str], time_s: ArrayLike, base_or_force: ArrayLike, response_g: ArrayLike,
              *, kind: Excitation = "base") -> Path:
    """Write one run record in the raw-data contract (``.csv``, ``.csv.gz`` or ``.mat``).

    Parameters
    ----------
    path : path-like
        Target; the suffix picks the format. CSV uses ``%.9g`` (round-trips the
        9 significant digits it keeps); gzip and MAT headers carry no timestamp,
        so equal data give equal bytes.
    time_s : array_like, shape (n,)
        Sample times (s).
    base_or_force : array_like, shape (n,)
        Base acceleration (g) for ``kind='base'``, force (lbf) for ``kind='force'`` or
        drive voltage (V) for ``kind='voltage'``.
    response_g : array_like, shape (n,)
        Response acceleration (g).
    kind : {'base', 'force', 'voltage'}, optional
        Excitation kind, which names the reference column.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    if kind not in REFERENCE:
        raise ValueError(f"kind must be one of {', '.join(REFERENCE)}, got {kind!r}")
    cols = {TIME: time_s, REFERENCE[kind]: base_or_force, RESPONSE: response_g}
    cols = {k: np.asarray(v, dtype=np.float64) for k, v in cols.items()}
    if len({v.shape for v in cols.values()}) != 1 or cols[TIME].ndim != 1:
        raise ValueError(f"time_s, {REFERENCE[kind]} and response_g must be 1-D of one length, "
                         f"got shapes {[v.shape for v in cols.values()]}")
    name = Path(path).name.lower()
    if name.endswith(".mat"):
        import scipy.io  # here: the workflow imports jointcal.io to name its jobs, every Snakemake run and stage

        buf = io.BytesIO()
        scipy.io.savemat(buf, cols, do_compression=True, oned_as="column")
        data = buf.getvalue()
        data = b"MATLAB 5.0 MAT-file, written by jointcal".ljust(116) + data[116:]
    elif name.endswith((".csv", ".csv.gz")):
        data = _csv_bytes(cols)
        if name.endswith(".gz"):
            data = gzip.compress(data, compresslevel=6, mtime=0)
    else:
        raise ValueError(f"{path}: unsupported suffix; use .csv, .csv.gz or .mat")
    return write_bytes_atomic(data, path)
