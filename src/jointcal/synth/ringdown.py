"""The virtual lab's ring-downs: a series item ``{test: ringdown, dwell_hz: [...], ...}``.

A ring-down is what a lab records when it cuts a shaker's drive off a steady dwell and lets the structure
ring: the record of a dwell (`jointcal.synth.dwell`: the drive held at each frequency of ``dwell_hz`` for
``dwell_s``, cut to zero, ``decay_s`` of free decay), whose manifest row names no frequency
(`jointcal.io.test_kind` ``ringdown``: the decay's start is found from the drive or the response).
"""
from __future__ import annotations

from .dwell import held_drive_rows

__all__ = ["plan"]


def plan(rows: list[dict], item: dict, assembly: str, seq: int, ref: str, fs: float, fmt: str) -> int:
    """Append one manifest row per frequency of a ring-down series `item`; return the last sequence.

    Raises
    ------
    ValueError
        No ``dwell_hz``, or a frequency at or above Nyquist.
    """
    return held_drive_rows(rows, item, assembly, seq, ref, fs, fmt, "ringdown")
