"""Run records as labs export them: UFF 58, NI TDMS and Simcenter Test.Lab MATLAB structs.

Private: `jointcal.io.read_run` calls `read_lab_export` for these files. Each format is
read by the library made for it (`jointcal.io._lab_channels`) into a list of `Channel`
(name(s), samples, time axis, unit); the manifest's ``reference_channel`` and
``response_channel`` pick two of them, and each is converted to the contract's unit of
its role (g, lbf or V) from the unit the format defines (`jointcal.io._lab_units`):

=========  ==============================================  =====================================
format     channel name                                    unit (and quantity)
=========  ==============================================  =====================================
UFF 58     ID line 1 (``id1``), or the response DOF as     the unit exponents (length, force) of
           ``node:+Z`` (``rsp_node``, ``rsp_dir``)         the specific data type (12
                                                           acceleration, 13 force) in data set
                                                           164's system (SI without one); with
                                                           all exponents 0, the units label
TDMS       the channel's name, or ``group/channel``        the ``unit_string`` property
Test.Lab   ``function_record.name`` (one per column of     SI of ``y_values.quantity``'s
           ``y_values.values``), or the variable's name    ``quantity_terms`` ("saved in MKS";
                                                           ``label`` is the unit shown); without
                                                           them ``unit``, or ``label`` when a unit
=========  ==============================================  =====================================

A label that disagrees with the stored quantity is named. A channel without a unit is
taken in the contract's unit of its role. The time axis is the file's start and
increment (UFF: ``abscissa_min``, ``abscissa_inc``; TDMS: ``wf_start_offset``,
``wf_increment``; Test.Lab: ``x_values.start_value``, ``x_values.increment``), the same
for both channels.
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import CHANNEL_COLUMNS, QUANTITY, REFERENCE, RESPONSE, TIME, UNITS, Excitation, fail
from jointcal.io._lab_channels import Channel, lab_channels
from jointcal.io._lab_units import unit_size

__all__ = ["LAB_SUFFIXES", "Channel", "is_testlab", "read_lab_export", "unit_size"]

LAB_SUFFIXES = (".uff", ".unv", ".tdms")  # and .mat files holding Test.Lab structs
FORMATS = {".uff": "UFF 58", ".unv": "UFF 58", ".tdms": "TDMS", ".mat": "Test.Lab MAT"}


def is_testlab(mat: Mapping[str, Any]) -> bool:
    """True when a loaded MAT file holds a Test.Lab struct (fields ``x_values`` and ``y_values``)."""
    for key, value in mat.items():
        names = getattr(getattr(value, "dtype", None), "names", None) or ()
        if not key.startswith("__") and {"x_values", "y_values"} <= set(names):
            return True
    return False


def read_lab_export(path: Path, kind: Excitation | None, channels: Mapping[str, str | None],
                    run_id: str | None, *, reference_path: Path | None = None,
                    no_reference: bool = False) -> tuple[dict[str, NDArray[np.float64]], dict[str, Any]]:
    """The contract's three columns from a lab export, with their sources (see `jointcal.io.read_run`).

    Parameters
    ----------
    path : Path
        A ``.uff``/``.unv``, ``.tdms`` or Test.Lab ``.mat`` file.
    kind : {'base', 'force', 'voltage'} or None
        The run's excitation (from the manifest's level column).
    channels : mapping
        ``{'reference': name, 'response': name}`` from the manifest row.
    run_id : str or None
        The run, named in messages.
    reference_path : Path, optional
        The lab's export that holds the reference channel, when not `path` (the manifest's
        ``reference_file``: Test.Lab exports the drive of a run apart, ``*_TimeShaker.mat``).
    no_reference : bool, optional
        True for a ring-down whose drive was not recorded (its ``reference_channel`` empty): the
        reference column is then zero throughout, its source 'not recorded'.
    """
    fmt = FORMATS[path.suffix.lower()]
    if kind is None:
        fail(path, f"a {fmt} record needs its manifest row (the level column gives its excitation)",
             "read it with read_run(path, row)")
    found = lab_channels(path, fmt)
    listed = ", ".join(repr(c.names[0]) for c in found) or "none"
    run = f" of run {run_id!r}" if run_id else ""
    ref_found = lab_channels(reference_path, FORMATS[reference_path.suffix.lower()]) if reference_path else found
    files = {"reference": (reference_path or path, ref_found), "response": (path, found)}
    picked, where = {}, {}
    for role, column in (("reference", REFERENCE[kind]), ("response", RESPONSE)):
        want = channels.get(role)
        if role == "reference" and no_reference and not want:
            continue
        file, chans = files[role]
        listed = ", ".join(repr(c.names[0]) for c in chans) or "none"
        if not want:
            fail(file, f"a {fmt} file names its channels, and the manifest's {CHANNEL_COLUMNS[role]}{run} is empty "
                 f"(the file's channels: {listed})", f"write the {role} channel's name there")
        hits = [c for c in chans if want in c.names] or [c for c in chans
                                                        if want.lower() in (n.lower() for n in c.names)]
        if not hits:
            fail(file, f"it has no channel {want!r} (named in {CHANNEL_COLUMNS[role]}{run}); the file's channels are "
                 f"{listed}", f"write one of them in {CHANNEL_COLUMNS[role]}")
        if len(hits) > 1:
            fail(file, f"{want!r} ({CHANNEL_COLUMNS[role]}{run}) names {len(hits)} channels "
                 f"({', '.join(repr(c.names[-1]) for c in hits)})", "write the full name (e.g. group/channel)")
        picked[column], where[column] = hits[0], (file, listed)
    resp = picked[RESPONSE]
    ref = picked.get(REFERENCE[kind], resp)
    if REFERENCE[kind] in picked and ref is resp:
        fail(path, f"reference_channel and response_channel{run} name one channel {ref.names[0]!r}",
             "name the reference (drive) and the response channels")
    if ref.values.size != resp.values.size or abs(ref.dt / resp.dt - 1) > 1e-9 or abs(ref.t0 - resp.t0) > ref.dt / 2:
        fail(path, f"channels {ref.names[0]!r} and {resp.names[0]!r} have different time axes ({ref.values.size} "
             f"and {resp.values.size} samples every {ref.dt:.6g} and {resp.dt:.6g} s from {ref.t0:g} and "
             f"{resp.t0:g} s)", "export both channels of the run from one acquisition")
    cols = {TIME: ref.t0 + ref.dt * np.arange(ref.values.size)}
    sources = {TIME: {"name": "the file's time axis", "unit": "s", "by": "file"}}
    if REFERENCE[kind] not in picked:  # a ring-down whose drive was not recorded
        cols[REFERENCE[kind]] = np.zeros(resp.values.size)
        sources[REFERENCE[kind]] = {"name": "not recorded", "unit": next(iter(UNITS[QUANTITY[kind]])), "by": "none"}
    for column, ch in picked.items():
        quantity = QUANTITY[kind] if column != RESPONSE else "acceleration"
        cols[column], sources[column] = _in_contract_unit(ch, quantity, column, where[column][0], where[column][1])
    return cols, {"format": fmt, "sources": sources}


def _in_contract_unit(ch: Channel, quantity: str, column: str, path: Path,
                      listed: str) -> tuple[NDArray[np.float64], dict[str, str]]:
    """A channel's samples in the contract's unit of its role, and where that unit came from."""
    role = "response" if column == RESPONSE else "reference"
    fix = f"name the {quantity} channel in {CHANNEL_COLUMNS[role]} (the file's channels: {listed})"
    if ch.quantity and ch.quantity != quantity:
        fail(path, f"channel {ch.names[0]!r} is {_a(ch.quantity)} in the file, but the {role} of this run "
             f"({column}) is {_a(quantity)}", fix)
    if ch.unit is None:
        return ch.values, {"name": ch.names[0], "unit": next(iter(UNITS[quantity])), "by": "none"}
    known = unit_size(ch.unit)
    if known is None:
        fail(path, f"channel {ch.names[0]!r} has the unit {ch.unit!r}, which jointcal does not read (it reads "
             f"{', '.join(u for q in QUANTITY.values() for u in UNITS[q])})",
             "export the channel in one of these units")
    got, name, size = known
    if got != quantity:
        fail(path, f"channel {ch.names[0]!r} is in {name}, {_a(got)}, but the {role} of this run ({column}) is "
             f"{_a(quantity)}", fix)
    return ch.values * size, {"name": ch.names[0], "unit": name, "by": "file"}


def _a(word: str) -> str:
    return f"{'an' if word[0] in 'aeiou' else 'a'} {word}"
