"""The interface every test-kind module fills: its manifest columns, its checks and how its record is read.

A test kind is the way a run was measured (the manifest's ``test`` column). `TestKind` holds its
contract row, the part the io layer acts on:

* ``needs``: the manifest columns a row of this kind must fill, beyond the identity, level, rate and
  file (``numbers``: those among them that are positive numbers);
* ``row``: its manifest row's own checks, ``row(out, rec, where) -> out`` (a sweep's band against its
  direction, a dwell's frequency below Nyquist), after the columns every kind shares;
* ``band``: the band its record's drive is checked over, ``band(row, drive, response, fs, path, run) ->
  (f0, f1, rate, f_meas)`` (a dwell is checked as a sweep of one frequency), and ``drive_ends(drive, fs,
  f0, f1, rate, f_meas, n) -> (f_first, f_last, tol)``, the drive's frequencies at its ends; ``band``
  None: no drive over a band to check, only the channels' data problems (``unchecked`` says so in
  runs.csv's ``response_units_check``);
* ``reference_optional``: a lab export may lack the reference channel (a ring-down whose drive was
  not recorded);
* ``swept``: read as a sweep, through its envelopes and the sweep read-out (`jointcal.measure.modal`);
  a kind that is not is read from its record by its read-out rule (`jointcal.measure.testkinds`).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["TestKind"]

Band = Callable[..., "tuple[float, float, float, float]"]
DriveEnds = Callable[..., "tuple[float, float, float]"]


@dataclass(frozen=True)
class TestKind:
    """One kind of test in the contract (see the module notes for each field).

    Attributes
    ----------
    name : str
        The word in the manifest's ``test`` column.
    needs : tuple of str
        The manifest columns a row of this kind must fill, beyond the identity, level, rate and file.
    what : str
        What the record holds, in words (the README's and the messages' phrase).
    """

    __test__ = False  # not a pytest test class, whatever its name

    name: str
    needs: tuple[str, ...]
    what: str
    row: Callable[[dict[str, Any], Mapping[str, str], str], dict[str, Any]]
    numbers: tuple[str, ...] = ()
    band: Band | None = None
    drive_ends: DriveEnds | None = None
    unchecked: str = ""
    reference_optional: bool = False
    swept: bool = False

    def __post_init__(self) -> None:
        if (self.band is None) != (self.drive_ends is None) or (self.band is None) == (not self.unchecked):
            raise ValueError(f"test kind {self.name}: give band and drive_ends together, or neither and say in "
                             "unchecked why its drive is not checked.")
        if not set(self.numbers) <= set(self.needs):
            raise ValueError(f"test kind {self.name}: numbers {self.numbers} must be among needs {self.needs}.")


def lower_direction(out: dict[str, Any], rec: Mapping[str, str], where: str) -> dict[str, Any]:
    """A row of a kind that needs no sweep: the sweep's words left as given (its direction lower-cased)."""
    out["direction"] = out["direction"].lower()
    return out

