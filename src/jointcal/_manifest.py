"""The campaign manifest: read ``manifest.csv`` and check every row (`read_manifest`, re-exported by `jointcal.io`).

Also `check_delimiter`, the comma check that `jointcal.io` runs on CSV records too.
"""
from __future__ import annotations

import gzip
import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from jointcal._contract import LEVEL, POSITIVE, TEXT, fail

__all__ = ["read_manifest", "check_delimiter"]


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
        to the manifest's folder). Extra columns are kept.

    Returns
    -------
    pandas.DataFrame
        One row per run in file order; numbers as float64 (``sequence`` int64),
        text stripped, ``direction`` lower-case.

    Raises
    ------
    CampaignError
        Missing file or column, empty or non-numeric cell, non-positive rate or
        frequency, band inconsistent with the direction or above Nyquist, or a
        duplicated ``run_id``, ``file`` or (``assembly``, ``sequence``).
    """
    path = Path(path)
    if not path.is_file():
        fail(path, "the manifest does not exist", "put manifest.csv (one row per run) in the campaign folder")
    check_delimiter(path)
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
    missing = [c for c in need if c not in raw.columns]
    if missing:
        fail(path, f"column(s) {', '.join(missing)} missing (found: {', '.join(raw.columns)})",
             f"use the header {','.join(need)}")
    if raw.empty:
        fail(path, "it lists no runs", "add one row per run")
    rows = [_manifest_row(rec, path, i + 2, levels[0]) for i, rec in enumerate(raw.to_dict("records"))]
    for i, rec in enumerate(rows):
        _check_name(rec, path, i + 2)
    df = pd.DataFrame(rows, columns=need + [c for c in raw.columns if c not in need])
    for keys in (["run_id"], ["file"], ["assembly", "sequence"]):
        dup = df.duplicated(keys, keep=False)
        if dup.any():
            first = df.loc[dup].iloc[0]
            same = dup & (df[keys] == first[keys]).all(axis=1)
            lines = ", ".join(str(i + 2) for i in np.flatnonzero(same))
            what = " ".join(f"{k} {first[k]!r}" if k != "sequence" else f"sequence {first[k]} of"
                            for k in reversed(keys))
            fail(path, f"lines {lines} repeat {what}", f"make each {' within '.join(reversed(keys))} unique")
    return df


DELIMITERS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}
SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]*")  # a file name on every system, not a path


def check_delimiter(path: Path) -> None:
    """Fail, naming the separator, when a CSV file's header is not split by commas."""
    try:
        with (gzip.open(path, "rt", encoding="utf-8-sig") if path.name.lower().endswith(".gz")
              else open(path, encoding="utf-8-sig")) as fh:
            head = fh.readline()
    except (OSError, EOFError, UnicodeDecodeError):
        return  # pandas' reader names the problem
    if "," not in head:
        for sep, name in DELIMITERS.items():
            if head.count(sep) >= 2:
                fail(path, f"its columns are separated by {name} ({sep!r}), not commas (header: {head.strip()!r})",
                     "save it as comma-separated text with '.' as the decimal point")


def _check_name(rec: dict[str, Any], path: Path, line: int) -> None:
    """Fail unless run_id is a safe file name and assembly holds no path separator."""
    rid, assembly = rec["run_id"], rec["assembly"]
    where = f"{path}: line {line} (run_id {rid!r})"
    if not SAFE_NAME.fullmatch(rid):
        bad = sorted({c for c in rid if not re.fullmatch(r"[A-Za-z0-9._+-]", c)}) or [rid[0]]
        fail(where, f"run_id {rid!r} is not a safe file name (it names the run's output files; "
             f"{', '.join(map(repr, bad))} not allowed there)",
             "use letters, digits, '.', '_', '+' and '-' only, starting with a letter or digit")
    if any(c in assembly for c in "/\\") or assembly.startswith("."):
        fail(where, f"assembly {assembly!r} is not a safe folder name (it names the calibration's output folder)",
             "write it without '/' or '\\' and not starting with '.'")


def _manifest_row(rec: dict[str, str], path: Path, line: int, level: str) -> dict[str, Any]:
    where = f"{path}: line {line} (run_id {rec['run_id'].strip()!r})"
    out: dict[str, Any] = {k: v.strip() for k, v in rec.items()}
    for col in (*TEXT, "sequence", level, *POSITIVE):
        if not out[col]:
            fail(where, f"{col} is empty", f"fill in {col}")
    try:
        out["sequence"] = int(out["sequence"])
    except ValueError:
        out["sequence"] = 0
    if out["sequence"] < 1:
        fail(where, f"sequence {rec['sequence'].strip()!r} is not an integer >= 1",
             "number the runs of each assembly 1, 2, 3, ... in test order")
    for col in (level, *POSITIVE):
        try:
            out[col] = float(out[col])
        except ValueError:
            out[col] = float("nan")
        if not (np.isfinite(out[col]) and out[col] > 0):
            fail(where, f"{col} {rec[col].strip()!r} is not a positive number", f"write {col} as a number > 0")
    out["direction"] = out["direction"].lower()
    f0, f1, fs = out["f_start_hz"], out["f_stop_hz"], out["sample_rate_hz"]
    if out["direction"] not in ("up", "down"):
        fail(where, f"direction {rec['direction'].strip()!r} is not up or down", "write up or down")
    if (out["direction"] == "up") != (f0 < f1) or f0 == f1:
        sweep = "an up" if out["direction"] == "up" else "a down"
        fail(where, f"{sweep} sweep cannot go from {f0:g} Hz to {f1:g} Hz",
             "use f_start_hz < f_stop_hz for up and f_start_hz > f_stop_hz for down")
    if max(f0, f1) >= fs / 2:
        fail(where, f"the band reaches {max(f0, f1):g} Hz, above Nyquist ({fs / 2:g} Hz)",
             "check the band and sample_rate_hz")
    return out
