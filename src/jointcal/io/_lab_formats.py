"""Run records as labs export them: UFF 58, NI TDMS and Simcenter Test.Lab MATLAB structs.

Private: `jointcal.io.read_run` calls `read_lab_export` for these files. Each format is
read by the library made for it (UFF 58: pyuff; TDMS: npTDMS; Test.Lab: scipy.io) into
a list of `Channel` (name(s), samples, time axis, unit); the manifest's
``reference_channel`` and ``response_channel`` pick two of them, and each is converted
to the contract's unit of its role (g, lbf or V) from the unit the file gives:

=========  ==============================================  ================================
format     channel name                                    unit (and quantity)
=========  ==============================================  ================================
UFF 58     ID line 1 (``id1``), or the response DOF as     ``ordinate_axis_units_lab``
           ``node:+Z`` (``rsp_node``, ``rsp_dir``)         (``ordinate_spec_data_type``:
                                                           12 acceleration, 13 force)
TDMS       the channel's name, or ``group/channel``        the ``unit_string`` property
Test.Lab   ``function_record.name`` (one per column of     ``y_values.quantity``: ``unit``,
           ``y_values.values``), or the variable's name    or ``label`` when it is a unit
                                                           (a quantity ``label`` such as
                                                           'Acceleration' is checked)
=========  ==============================================  ================================

A channel without a unit is taken in the contract's unit of its role. The time axis is
the file's start and increment (UFF: ``abscissa_min``, ``abscissa_inc``; TDMS:
``wf_start_offset``, ``wf_increment``; Test.Lab: ``x_values.start_value``,
``x_values.increment``), the same for both channels.
"""
from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io
from numpy.typing import NDArray

from jointcal.io._contract import (
    CHANNEL_COLUMNS, QUANTITY, REFERENCE, RESPONSE, TIME, UNITS, Excitation, fail,
)

__all__ = ["LAB_SUFFIXES", "Channel", "is_testlab", "read_lab_export", "unit_size"]

LAB_SUFFIXES = (".uff", ".unv", ".tdms")  # and .mat files holding Test.Lab structs
FORMATS = {".uff": "UFF 58", ".unv": "UFF 58", ".tdms": "TDMS", ".mat": "Test.Lab MAT"}
UFF_QUANTITY = {8: "displacement", 9: "force", 11: "velocity", 12: "acceleration", 13: "force", 15: "pressure"}
UFF_TIME, UFF_DIRS = 17, {1: "X", 2: "Y", 3: "Z", 4: "RX", 5: "RY", 6: "RZ"}
QUANTITY_WORDS = {"acceleration": "acceleration", "force": "force", "voltage": "voltage", "time": "time",
                  "displacement": "displacement", "velocity": "velocity", "pressure": "pressure"}


@dataclass(frozen=True)
class Channel:
    """One recorded channel of a lab export.

    Attributes
    ----------
    names : tuple of str
        The names it answers to, the first shown in messages.
    values : ndarray of float, shape (n,)
        Samples in the file's unit.
    t0, dt : float
        Time of the first sample and the sample interval (s).
    unit : str or None
        The unit the file gives ('g', 'm/s^2', 'N', 'V', ...), None when it gives none.
    quantity : str or None
        The quantity the file gives ('acceleration', 'force', ...), None when it gives none.
    """

    names: tuple[str, ...]
    values: NDArray[np.float64]
    t0: float
    dt: float
    unit: str | None = None
    quantity: str | None = None


def unit_size(text: str) -> tuple[str, str, float] | None:
    """The quantity, canonical name and size (in the contract's unit) of a unit's text; None if unknown.

    Spellings are forgiven: case, spaces, '^' and '**', '²' ('m/s2', 'M/S^2', 'm/s**2').
    """
    key = _unit_key(text)
    for quantity, units in UNITS.items():
        for name, size in units.items():
            if _unit_key(name) == key:
                return quantity, name, size
    return None


def _unit_key(text: str) -> str:
    return re.sub(r"[\s^*]", "", str(text)).replace("²", "2").lower().replace("sec", "s")


def is_testlab(mat: Mapping[str, Any]) -> bool:
    """True when a loaded MAT file holds a Test.Lab struct (fields ``x_values`` and ``y_values``)."""
    for key, value in mat.items():
        names = getattr(getattr(value, "dtype", None), "names", None) or ()
        if not key.startswith("__") and {"x_values", "y_values"} <= set(names):
            return True
    return False


def read_lab_export(path: Path, kind: Excitation | None, channels: Mapping[str, str | None],
                    run_id: str | None) -> tuple[dict[str, NDArray[np.float64]], dict[str, Any]]:
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
    """
    fmt = FORMATS[path.suffix.lower()]
    if kind is None:
        fail(path, f"a {fmt} record needs its manifest row (the level column gives its excitation)",
             "read it with read_run(path, row)")
    found = {"UFF 58": _uff_channels, "TDMS": _tdms_channels, "Test.Lab MAT": _testlab_channels}[fmt](path)
    listed = ", ".join(repr(c.names[0]) for c in found) or "none"
    run = f" of run {run_id!r}" if run_id else ""
    picked = {}
    for role, column in (("reference", REFERENCE[kind]), ("response", RESPONSE)):
        want = channels.get(role)
        if not want:
            fail(path, f"a {fmt} file names its channels, and the manifest's {CHANNEL_COLUMNS[role]}{run} is empty "
                 f"(the file's channels: {listed})", f"write the {role} channel's name there")
        hits = [c for c in found if want in c.names] or [c for c in found
                                                        if want.lower() in (n.lower() for n in c.names)]
        if not hits:
            fail(path, f"it has no channel {want!r} (named in {CHANNEL_COLUMNS[role]}{run}); the file's channels are "
                 f"{listed}", f"write one of them in {CHANNEL_COLUMNS[role]}")
        if len(hits) > 1:
            fail(path, f"{want!r} ({CHANNEL_COLUMNS[role]}{run}) names {len(hits)} channels "
                 f"({', '.join(repr(c.names[-1]) for c in hits)})", "write the full name (e.g. group/channel)")
        picked[column] = hits[0]
    ref, resp = picked[REFERENCE[kind]], picked[RESPONSE]
    if ref is resp:
        fail(path, f"reference_channel and response_channel{run} name one channel {ref.names[0]!r}",
             "name the reference (drive) and the response channels")
    if ref.values.size != resp.values.size or abs(ref.dt / resp.dt - 1) > 1e-9 or abs(ref.t0 - resp.t0) > ref.dt / 2:
        fail(path, f"channels {ref.names[0]!r} and {resp.names[0]!r} have different time axes ({ref.values.size} "
             f"and {resp.values.size} samples every {ref.dt:.6g} and {resp.dt:.6g} s from {ref.t0:g} and "
             f"{resp.t0:g} s)", "export both channels of the run from one acquisition")
    cols = {TIME: ref.t0 + ref.dt * np.arange(ref.values.size)}
    sources = {TIME: {"name": "the file's time axis", "unit": "s", "by": "file"}}
    for column, ch in picked.items():
        quantity = QUANTITY[kind] if column != RESPONSE else "acceleration"
        cols[column], sources[column] = _in_contract_unit(ch, quantity, column, path, listed)
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


def _uff_channels(path: Path) -> list[Channel]:
    """The time records (data-set 58) of a UFF file (pyuff)."""
    import pyuff

    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions for malformed files
        fail(path, f"cannot be read as a universal file ({type(exc).__name__}: {exc})",
             "export the run as UFF 58 time records (one data-set 58 per channel)")
    sets = [s for s in (sets if isinstance(sets, list) else [sets]) if s.get("type") == 58]
    if not sets:
        fail(path, "it holds no data-set 58 (function at a nodal DOF)",
             "export the run's channels as UFF 58 time records")
    out = []
    for s in sets:
        direction = int(s.get("rsp_dir", 0))
        dof = f"{s.get('rsp_node')}:{'+' if direction >= 0 else '-'}{UFF_DIRS.get(abs(direction), '')}"
        name = str(s.get("id1", "")).strip()
        if s.get("abscissa_spec_data_type") not in (0, 1, UFF_TIME) or not s.get("abscissa_spacing"):
            fail(path, f"record {name!r} is not an evenly sampled time record (abscissa type "
                 f"{s.get('abscissa_spec_data_type')}, spacing {s.get('abscissa_spacing')})",
                 "export the time records of the run, not spectra or FRFs")
        data = np.asarray(s["data"])
        if np.iscomplexobj(data):
            fail(path, f"record {name!r} holds complex values (a spectrum)", "export the time records of the run")
        dt = float(s["abscissa_inc"]) * _time_scale(s.get("abscissa_axis_units_lab"), path, name)
        out.append(Channel((name, dof) if name and name != "NONE" else (dof,), data.astype(np.float64),
                           float(s.get("abscissa_min", 0.0)), dt, _label(s.get("ordinate_axis_units_lab")),
                           UFF_QUANTITY.get(int(s.get("ordinate_spec_data_type", 0)))))
    return out


def _tdms_channels(path: Path) -> list[Channel]:
    """The waveform channels of an NI TDMS file (npTDMS)."""
    from nptdms import TdmsFile

    try:
        tdms = TdmsFile.read(str(path))
    except Exception as exc:  # npTDMS raises ValueError, KeyError, ... for malformed files
        fail(path, f"cannot be read as a TDMS file ({type(exc).__name__}: {exc})", "save the run with NI's TDMS writer")
    out = []
    for group in tdms.groups():
        for ch in group.channels():
            props = ch.properties
            if "wf_increment" not in props:
                fail(path, f"channel '{group.name}/{ch.name}' has no wf_increment (the sample interval)",
                     "save the channels as waveforms (wf_increment, wf_start_offset)")
            out.append(Channel((ch.name, f"{group.name}/{ch.name}"), np.asarray(ch[:], dtype=np.float64),
                               float(props.get("wf_start_offset", 0.0)), float(props["wf_increment"]),
                               _label(props.get("unit_string"))))
    return out


def _testlab_channels(path: Path) -> list[Channel]:
    """The signals of a Simcenter Test.Lab MATLAB export (scipy.io)."""
    mat = scipy.io.loadmat(path, simplify_cells=True)
    out = []
    for var, sig in mat.items():
        if var.startswith("__") or not isinstance(sig, dict) or not {"x_values", "y_values"} <= set(sig):
            continue
        x, y = sig["x_values"], sig["y_values"]
        values = np.asarray(y.get("values"), dtype=np.float64)
        values = values[:, None] if values.ndim == 1 else values
        if values.ndim != 2 or not {"start_value", "increment"} <= set(x):
            fail(path, f"struct {var!r} lacks x_values.start_value / x_values.increment or a numeric "
                 "y_values.values", "export the time signals from Test.Lab with their x_values")
        names = (sig.get("function_record") or {}).get("name", var)
        names = [names] if isinstance(names, str) else [str(n) for n in np.atleast_1d(names)]
        quantities = y.get("quantity") or {}
        quantities = quantities if isinstance(quantities, list) else [quantities] * values.shape[1]
        scale = _time_scale(((x.get("quantity") or {}).get("unit")), path, var)
        for j in range(values.shape[1]):
            unit, quantity = _testlab_unit(quantities[j] if j < len(quantities) else {})
            aliases = (names[j],) if j < len(names) else ()
            aliases += (var,) if values.shape[1] == 1 else (f"{var}:{j + 1}",)
            out.append(Channel(aliases, values[:, j], float(x["start_value"]), float(x["increment"]) * scale,
                               unit, quantity))
    return out


def _testlab_unit(q: Mapping[str, Any]) -> tuple[str | None, str | None]:
    """(unit, quantity) of a Test.Lab ``quantity`` struct: its ``unit``, or its ``label`` when that is a unit;
    a ``label`` naming a quantity ('Acceleration') gives the quantity."""
    label = _label(q.get("label"))
    unit = _label(q.get("unit")) or (label if label and unit_size(label) else None)
    return unit, (QUANTITY_WORDS.get(label.lower()) if label else None)


def _a(word: str) -> str:
    return f"{'an' if word[0] in 'aeiou' else 'a'} {word}"


def _label(text: object) -> str | None:
    """A unit or quantity label, None when empty or 'NONE' (pyuff's placeholder)."""
    text = str(text).strip() if text is not None else ""
    return None if not text or text.upper() == "NONE" else text


def _time_scale(unit: object, path: Path, name: str) -> float:
    """Seconds per unit of a time axis's label (1 when unlabelled)."""
    label = _label(unit)
    if label is None:
        return 1.0
    known = unit_size(label)
    if known is None or known[0] != "time":
        fail(path, f"the time axis of {name!r} is in {label!r}, not a time unit", "export the signals against time")
    return known[2]
