"""The campaign manifest: read ``manifest.csv`` and check every row (`read_manifest`, re-exported by `jointcal.io`).

Also `check_csv_text`, the checks of a CSV file's bytes and first lines (compression,
separator, trailing commas) that `jointcal.io` runs on CSV records too.
"""
from __future__ import annotations

import gzip
import os
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from jointcal.io.contract import LEVEL, POSITIVE, REF_FILE, TEXT, CampaignWarning, fail
from jointcal.io.testkinds import DEFAULT, TEST, TEST_KINDS, kind_columns, manifest_kind

__all__ = ["read_manifest", "check_csv_text"]

DELIMITERS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}
SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]*")  # a file name on every system, not a path
MAGIC = {b"\x1f\x8b": "gzip-compressed", b"PK\x03\x04": "a zip archive (an Excel workbook?)"}


def read_manifest(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read and validate a campaign's ``manifest.csv``.

    Parameters
    ----------
    path : path-like
        The manifest file. Columns: ``run_id``, ``assembly``, ``sequence`` (order of
        the run within its assembly, integer >= 1), ``level_g`` (base acceleration
        amplitude, g), ``level_lbf`` (force amplitude, lbf) or ``level_V`` (drive
        voltage amplitude, V), ``direction``
        (``up``/``down``), ``f_start_hz``, ``f_stop_hz`` (Hz),
        ``sweep_rate_hz_per_s`` (Hz/s), ``sample_rate_hz`` (Hz) and ``file`` (relative
        to the manifest's folder, written with '/'). Optional: ``sweep_start_s`` (s,
        the sweep's start after the record's first sample; empty or 0 when the record
        starts with the sweep), ``reference_channel`` and ``response_channel`` (the
        channel names in a lab format's file), ``test`` (the run's kind: ``sweep``,
        the default when the column is absent or the cell empty, ``dwell`` or ``ringdown``;
        `jointcal.io.testkinds`) and ``dwell_hz`` (Hz, a dwell's drive frequency). A run of
        another kind than ``sweep`` may leave ``direction``, ``f_start_hz``, ``f_stop_hz``
        and ``sweep_rate_hz_per_s`` empty, and a campaign without sweeps may leave those
        columns out. Extra columns are kept.

    Returns
    -------
    pandas.DataFrame
        One row per run in file order; numbers as float64 (``sequence`` int64),
        text stripped, ``direction`` and ``test`` lower-case (``test`` empty -> ``sweep``),
        a sweep column a run does not need NaN when empty. Rows whose every cell is empty
        (a spreadsheet's trailing rows) are left out with a `CampaignWarning`.

    Raises
    ------
    CampaignError
        Missing file or column, a file that is not comma-separated text, empty or
        non-numeric cell, non-positive rate or frequency, a ``test`` that is no kind,
        a dwell without ``dwell_hz`` or with it above Nyquist, band inconsistent with the
        direction or above Nyquist, a duplicated ``run_id`` or (``assembly``,
        ``sequence``), one record listed twice (under any spelling), a ``file``
        written with a Windows backslash, or a listed file that does not exist.
    """
    path = Path(path)
    if not path.is_file():
        fail(path, "the manifest does not exist", "put manifest.csv (one row per run) in the campaign folder")
    check_csv_text(path)
    try:
        raw = pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8-sig")
    except (ValueError, UnicodeDecodeError) as exc:
        fail(path, f"cannot be read as CSV ({exc})", "save it as comma-separated UTF-8 text with one header line")
    raw.columns = [str(c).strip() for c in raw.columns]
    levels = [c for c in LEVEL.values() if c in raw.columns]
    if len(levels) != 1:
        found = " and ".join(levels) or "neither"
        fail(path, f"it needs exactly one of the columns {', '.join(LEVEL.values())} (found {found})",
             "give level_g for base-driven, level_lbf for force-driven or level_V for voltage-driven campaigns")
    need = ["run_id", "assembly", "sequence", levels[0], "direction", *POSITIVE, "file"]
    kinds = raw[TEST].str.strip().str.lower() if TEST in raw.columns else pd.Series("", index=raw.index)
    present = [k for k in TEST_KINDS.values() if kinds.replace("", DEFAULT).isin([k.name]).any()]
    needed = {c for k in present for c in k.needs}  # the columns of the kinds the campaign holds
    header = [c for c in need if c not in kind_columns() or c in needed]
    header += [c for k in present for c in k.needs if c not in header]
    missing = [c for c in header if c not in raw.columns]
    if missing:
        fail(path, f"column(s) {', '.join(missing)} missing (found: {', '.join(raw.columns)})",
             f"use the header {','.join(header)}")
    for col in need:
        if col not in raw.columns:  # a sweep column of a campaign without sweeps: empty
            raw[col] = ""
    empty = (raw.apply(lambda c: c.str.strip()) == "").all(axis=1).to_numpy()
    if empty.any():
        lines = _ranges(np.flatnonzero(empty) + 2)
        warnings.warn(f"{path}: {lines} {'is' if empty.sum() == 1 else 'are'} empty (a spreadsheet's trailing "
                      "rows?) and left out; delete them from the manifest.", CampaignWarning, stacklevel=2)
    lines = np.flatnonzero(~empty) + 2  # line numbers count the header as line 1
    raw = raw.loc[~empty]
    if raw.empty:
        fail(path, "it lists no runs", "add one row per run")
    rows = [_manifest_row(rec, path, line, levels[0]) for line, rec in zip(lines, raw.to_dict("records"))]
    for line, rec in zip(lines, rows):
        _check_name(rec, path, line)
    df = pd.DataFrame(rows, columns=need + [c for c in raw.columns if c not in need])
    for keys in (["run_id"], ["assembly", "sequence"]):
        dup = df.duplicated(keys, keep=False).to_numpy()
        if dup.any():
            first = df.loc[dup].iloc[0]
            same = dup & (df[keys] == first[keys]).all(axis=1).to_numpy()
            what = " ".join(f"{k} {first[k]!r}" if k != "sequence" else f"sequence {first[k]} of"
                            for k in reversed(keys))
            fail(path, f"lines {', '.join(map(str, lines[same]))} repeat {what}",
                 f"make each {' within '.join(reversed(keys))} unique")
    _check_files(df, path, lines)
    return df


def _ranges(lines: np.ndarray) -> str:
    """'line 7' or 'lines 27-30' or 'lines 3, 9' for sorted line numbers."""
    if lines.size == 1:
        return f"line {lines[0]}"
    if (np.diff(lines) == 1).all():
        return f"lines {lines[0]}-{lines[-1]}"
    return "lines " + ", ".join(map(str, lines))


def check_csv_text(path: Path) -> None:
    """Fail, naming the cause directly, when a CSV file is compressed otherwise than its name says,
    is not split by commas, or ends every line with a comma."""
    try:
        with open(path, "rb") as fh:
            magic = fh.read(4)
    except OSError:
        return  # the reader names the problem
    gz = path.name.lower().endswith(".gz")
    kind = next((what for head, what in MAGIC.items() if magic.startswith(head)), None)
    if kind and not (gz and magic.startswith(b"\x1f\x8b")):
        stem = re.sub(r"(\.csv)?(\.gz)?$", "", path.name, flags=re.I)
        fix = (f"rename it {stem}.csv.gz (also in the manifest's file column) or decompress it"
               if magic.startswith(b"\x1f\x8b") else "save it from the spreadsheet as 'CSV UTF-8 (comma delimited)'")
        fail(path, f"it is {kind} but named {path.suffix}, not CSV text", fix)
    if gz and not magic.startswith(b"\x1f\x8b"):
        fail(path, "it is named .gz but is not gzip-compressed", f"rename it {path.name[:-3]} or compress it with gzip")
    try:
        with (gzip.open(path, "rt", encoding="utf-8-sig") if gz else open(path, encoding="utf-8-sig")) as fh:
            head = [fh.readline() for _ in range(6)]
    except (OSError, EOFError, UnicodeDecodeError):
        return  # pandas' reader names the problem
    head = [h.rstrip("\r\n") for h in head if h.strip()]
    if not head:
        return
    if "," not in head[0]:
        for sep, name in DELIMITERS.items():
            if head[0].count(sep) >= 2:
                fail(path, f"its columns are separated by {name} ({sep!r}), not commas (header: {head[0].strip()!r})",
                     "save it as comma-separated text with '.' as the decimal point")
    ends = [h.rstrip().endswith(",") for h in head]
    if ends[0] or (len(ends) > 1 and all(ends[1:])):
        which = "every line" if all(ends) else ("the header" if ends[0] else "every data line")
        line = head[min(1, len(head) - 1)]
        fail(path, f"{which} ends with a comma, which adds an empty last column (line 2: {line!r})",
             "remove the trailing commas (save it again with only the columns of the contract)")


def _check_name(rec: dict[str, Any], path: Path, line: int) -> None:
    """Fail unless run_id is a safe file name, assembly holds no path separator and file no backslash."""
    rid, assembly, file = rec["run_id"], rec["assembly"], rec["file"]
    where = f"{path}: line {line} (run_id {rid!r})"
    if not SAFE_NAME.fullmatch(rid):
        bad = sorted({c for c in rid if not re.fullmatch(r"[A-Za-z0-9._+-]", c)}) or [rid[0]]
        fail(where, f"run_id {rid!r} is not a safe file name (it names the run's output files; "
             f"{', '.join(map(repr, bad))} not allowed there)",
             "use letters, digits, '.', '_', '+' and '-' only, starting with a letter or digit")
    if any(c in assembly for c in "/\\") or assembly.startswith("."):
        fail(where, f"assembly {assembly!r} is not a safe folder name (it names the calibration's output folder)",
             "write it without '/' or '\\' and not starting with '.'")
    if "\\" in file:
        fail(where, f"file '{file}' is written with a Windows backslash ('\\') as the folder separator",
             f"write it with '/' ({file.replace(chr(92), '/')}), which works on every system")


def _check_files(df: pd.DataFrame, path: Path, lines: np.ndarray) -> None:
    """Fail when two rows name one record (under any spelling) or a listed record does not exist."""
    folder = path.parent
    resolved = [str((folder / f).resolve()) for f in df["file"]]
    seen: dict[str, int] = {}
    for i, r in enumerate(resolved):
        if r in seen:
            j = seen[r]
            a, b = df["file"].iloc[j], df["file"].iloc[i]
            spelled = f"file {a!r}" if a == b else f"one file, as {a!r} and {b!r}"
            fail(path, f"lines {lines[j]}, {lines[i]} (runs {df['run_id'].iloc[j]!r}, {df['run_id'].iloc[i]!r}) "
                 f"name {spelled}", "give each run its own record file")
        seen[r] = i
    for i, (rid, file) in enumerate(zip(df["run_id"], df["file"])):
        if not (folder / file).is_file():
            fail(folder / file, f"the file of run {rid!r} listed in manifest.csv (line {lines[i]}) does not exist",
                 "add the file or correct its name in the manifest's file column")
    for i, (rid, ref) in enumerate(zip(df["run_id"], df.get(REF_FILE, [""] * len(df)))):
        if ref and not (folder / ref).is_file():
            fail(folder / ref, f"the reference_file of run {rid!r} listed in manifest.csv (line {lines[i]}) does "
                 "not exist", "add the file or correct its name in the manifest's reference_file column")


def _manifest_row(rec: dict[str, str], path: Path, line: int, level: str) -> dict[str, Any]:
    where = f"{path}: line {line} (run_id {rec['run_id'].strip()!r})"
    out: dict[str, Any] = {k: v.strip() for k, v in rec.items()}
    kind = manifest_kind(rec, where)
    if TEST in out:
        out[TEST] = kind.name
    needed = [c for c in (*TEXT, "sequence", level, *POSITIVE) if c not in kind_columns()] + list(kind.needs)
    for col in needed:
        if not out.get(col, ""):
            what = "" if kind.name == DEFAULT else f" (a {kind.name} run needs it)"
            fail(where, f"{col} is empty{what}", f"fill in {col}")
    try:
        out["sequence"] = int(out["sequence"])
    except ValueError:
        out["sequence"] = 0
    if out["sequence"] < 1:
        fail(where, f"sequence {rec['sequence'].strip()!r} is not an integer >= 1",
             "number the runs of each assembly 1, 2, 3, ... in test order")
    numbers = dict.fromkeys(c for k in TEST_KINDS.values() for c in k.numbers if c not in POSITIVE)
    for col in (level, *POSITIVE, *numbers):
        if col not in out or (col not in needed and not out[col]):
            if col in out or col in POSITIVE:
                out[col] = float("nan")  # a column this kind does not need, left empty
            continue
        try:
            out[col] = float(out[col])
        except ValueError:
            out[col] = float("nan")
        if not (np.isfinite(out[col]) and out[col] > 0):
            fail(where, f"{col} {rec[col].strip()!r} is not a positive number", f"write {col} as a number > 0")
    return kind.row(out, rec, where)  # the kind's own checks (`jointcal.io.testkinds`)
