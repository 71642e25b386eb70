"""sweep: a linear sine sweep (the default kind: the ``test`` column absent or the cell empty)."""
from __future__ import annotations

from typing import Any

import numpy as np

from jointcal.io._band import drive_band
from jointcal.io.contract import START, fail
from .kind import TestKind

__all__ = ["KIND", "SWEEP_ONLY"]

SWEEP_ONLY = ("direction", "f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s")  # the columns only a sweep needs


def _row(out: dict[str, Any], rec, where: str) -> dict[str, Any]:
    """A sweep's row: its start, direction and band checked (the contract before test kinds)."""
    if START in out:
        text = out[START]
        try:
            out[START] = float(text) if text else 0.0
        except ValueError:
            out[START] = float("nan")
        if not (np.isfinite(out[START]) and out[START] >= 0):
            fail(where, f"{START} {text!r} is not a number >= 0",
                 "write the sweep's start in seconds after the record's first sample (empty or 0 when the record "
                 "starts with the sweep)")
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


def _band(row, drive, response, fs, path, run):
    """The manifest's band."""
    return float(row["f_start_hz"]), float(row["f_stop_hz"]), float(row["sweep_rate_hz_per_s"]), float("nan")


def _drive_ends(drive, fs, f0, f1, rate, f_meas, n):
    """The drive's frequency at the sweep's start and end, measured (`jointcal.io._band.drive_band`)."""
    return drive_band(drive, fs, f0, f1, rate)


KIND = TestKind("sweep", SWEEP_ONLY, "a linear sine sweep (the default)", _row,
                numbers=("f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s"), band=_band, drive_ends=_drive_ends,
                swept=True)
