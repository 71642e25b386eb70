"""dwell: a steady sine at ``dwell_hz``, possibly followed by its ring-down after the drive is cut."""
from __future__ import annotations

from typing import Any

import numpy as np

from jointcal.io._band import dwell_band
from jointcal.io.contract import fail
from .kind import TestKind

__all__ = ["KIND", "DWELL"]

DWELL = "dwell_hz"  # manifest column: a dwell's frequency (Hz)


def _row(out: dict[str, Any], rec, where: str) -> dict[str, Any]:
    """A dwell's row: its frequency below Nyquist; the sweep's words left as given."""
    out["direction"] = out["direction"].lower()
    fs = out["sample_rate_hz"]
    if out[DWELL] >= fs / 2:
        fail(where, f"dwell_hz {out[DWELL]:g} Hz is above Nyquist ({fs / 2:g} Hz)",
             "check dwell_hz and sample_rate_hz")
    return out


def _band(row, drive, response, fs, path, run):
    """Its amplitude checks over the dwell, as over a sweep of one frequency (`jointcal.io._band.dwell_band`)."""
    live = drive[np.isfinite(drive)]
    if live.size and live.min() < live.max():
        return dwell_band(drive, fs, float(row[DWELL]), path, run, response)
    return (float(row[DWELL]),) * 2 + (1.0, np.nan)


def _drive_ends(drive, fs, f0, f1, rate, f_meas, n):
    """The drive's frequency over the dwell's second half, within one FFT bin plus 0.1 %."""
    return f_meas, f_meas, fs * 2 / n + 1e-3 * f0


KIND = TestKind("dwell", (DWELL,), "a steady sine at dwell_hz, possibly followed by its ring-down after the cut",
                _row, numbers=(DWELL,), band=_band, drive_ends=_drive_ends)
