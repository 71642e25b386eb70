"""The virtual lab's dwells: a series item ``{test: dwell, dwell_hz: [...], ...}``.

A series item with ``test: dwell`` makes one run per frequency of ``dwell_hz`` (Hz): the drive held
at that frequency for ``dwell_s`` (s, default 1.0) with the controller's ripple and the shaker's
distortion, switched on and cut to zero without the sweep's ramps (a ramp-down would take the
response down with the drive, quasi-statically: a 2 g Ministack dwell ramped down over 0.05 s
leaves 0.22 g of its 50 g to ring down), then ``decay_s`` (s, default 0.5) of free decay recorded
(`jointcal.io.test_kind` ``dwell``: the steady point and the ring-down). The drive is
`jointcal.synth.daq.controlled_sweep` over a band of `TINY` of the frequency (`drive_band`), so the
measurement chain is the sweeps'. A ring-down (`jointcal.synth.ringdown`) is the same record.
"""
from __future__ import annotations

import numpy as np

from ..io.testkinds import DWELL, TEST_KINDS

__all__ = ["plan", "drive_band", "PRIVATE", "TINY"]

TINY = 1e-9  # the dwell's relative band: one frequency, the sweep's drive generator
PRIVATE = ("drive_hz", "dwell_s", "decay_s")  # plan columns the manifest does not show


def plan(rows: list[dict], item: dict, assembly: str, seq: int, ref: str, fs: float, fmt: str) -> int:
    """Append one manifest row per frequency of a dwell series `item`; return the last sequence.

    Raises
    ------
    ValueError
        No ``dwell_hz``, or a frequency at or above Nyquist.
    """
    return held_drive_rows(rows, item, assembly, seq, ref, fs, fmt, "dwell")


def held_drive_rows(rows: list[dict], item: dict, assembly: str, seq: int, ref: str, fs: float, fmt: str,
                    kind: str) -> int:
    """Rows of a held drive cut off into its free decay, one per frequency of ``dwell_hz``: a ``dwell`` names its
    frequency in the manifest, a ``ringdown`` does not."""
    from .spec import RIG_LEVEL

    freqs = [float(f) for f in np.atleast_1d(item.get("dwell_hz", []))]
    if not freqs or not all(0 < f < fs / 2 for f in freqs):
        raise ValueError(f"series item {item}: test must be dwell or ringdown with dwell_hz a list of frequencies "
                         f"between 0 and Nyquist ({fs / 2:g} Hz).")
    key = RIG_LEVEL[ref]
    unit = key.split("_")[1]
    for _ in range(int(item.get("repeats", 1))):
        for f in freqs:
            seq += 1
            run_id = f"{assembly}_{seq:02d}_{item[key]:g}{unit}_{kind}_{f:g}Hz"
            level = {key: float(item[key])} if ref != "force" else {"level_V": float(item[key]), "level_lbf": np.nan}
            rows.append(dict(run_id=run_id, assembly=assembly, sequence=seq, **level, direction="",
                             f_start_hz=np.nan, f_stop_hz=np.nan, sweep_rate_hz_per_s=np.nan, sample_rate_hz=fs,
                             file=f"runs/{run_id}.{fmt}", test=kind, dwell_hz=f if DWELL in TEST_KINDS[kind].needs else np.nan,
                             drive_hz=f, dwell_s=float(item.get("dwell_s", 1.0)),
                             decay_s=float(item.get("decay_s", 0.5))))
    return seq


def drive_band(row) -> tuple[float, float, float, float]:
    """(f_start, f_stop, rate, tail_s) of the drive generator for a planned dwell or ring-down row."""
    f = float(row.drive_hz)
    return f, f * (1 + TINY), f * TINY / float(row.dwell_s), float(row.decay_s)
