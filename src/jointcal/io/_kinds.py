"""The test kinds of the raw-data contract: which manifest columns each kind needs (`TestKind`, `KINDS`).

A run's ``test`` column names its kind: ``sweep`` (the default: the column absent or the cell
empty, exactly the contract before kinds), ``dwell`` (a steady sine at ``dwell_hz``, which may
be followed by its ring-down after the drive is cut) or ``ringdown`` (a free decay, after an
impact or a drive cut off). Each kind names the manifest columns it needs; the sweep's columns
a run of another kind does not need may be left empty for it.

Private: `jointcal.io._manifest` checks each row with `manifest_kind` and `KINDS`;
`jointcal.io._checks` checks a record with the kind's band (`dwell_band`).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from jointcal.io.contract import fail

__all__: list[str] = []

TEST, DWELL = "test", "dwell_hz"  # manifest columns: the run's kind; a dwell's frequency (Hz)
REF_FILE = "reference_file"  # optional manifest column: the lab export holding the reference, when apart
SWEEP_ONLY = ("direction", "f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s")


@dataclass(frozen=True)
class TestKind:
    """One kind of test in the contract.

    Attributes
    ----------
    name : str
        The word in the manifest's ``test`` column.
    needs : tuple of str
        The manifest columns a row of this kind must fill, beyond the identity, level, rate and file.
    what : str
        What the record holds, in words (the README's and the messages' phrase).
    """

    name: str
    needs: tuple[str, ...]
    what: str


KINDS: dict[str, TestKind] = {k.name: k for k in (
    TestKind("sweep", SWEEP_ONLY, "a linear sine sweep (the default)"),
    TestKind("dwell", (DWELL,), "a steady sine at dwell_hz, possibly followed by its ring-down after the cut"),
    TestKind("ringdown", (), "a free decay, after an impact or a drive cut off"),
)}


def manifest_kind(rec: Mapping[str, Any], where: str) -> TestKind:
    """The kind a manifest row names in ``test`` (``sweep`` when the column is absent or the cell empty).

    Raises
    ------
    CampaignError
        A ``test`` value that is none of `KINDS`.
    """
    word = str(rec.get(TEST, "") or "").strip().lower()
    if not word:
        return KINDS["sweep"]
    if word not in KINDS:
        fail(where, f"test {str(rec[TEST]).strip()!r} is not a test kind of the contract",
             f"write {', '.join(KINDS)} (empty is sweep)")
    return KINDS[word]


def kind_of(row: Mapping[str, Any]) -> str:
    """The kind's name of a checked row (``sweep`` when it has no ``test`` or it is empty/NaN)."""
    word = row.get(TEST, "")
    return word if isinstance(word, str) and word in KINDS else "sweep"
