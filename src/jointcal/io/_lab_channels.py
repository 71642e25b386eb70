"""The channels of a lab export, each read by the library made for its format, and the file checked whole.

Private: `jointcal.io._lab_formats.read_lab_export` calls `lab_channels`. UFF 58 is read
by pyuff, NI TDMS by npTDMS, a Simcenter Test.Lab MATLAB export by scipy.io; each
channel's unit by `jointcal.io._lab_units`. A file cut short is said as such (a UFF
file whose last data set lacks its closing ``-1``, a TDMS segment that runs past the
file's end, a Test.Lab signal with fewer values than its ``number_of_values``), and a
sample interval that is not a positive number stops the read.
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import fail
from jointcal.io._lab_units import label, testlab_unit, uff_unit, unit_size

__all__ = ["Channel", "lab_channels"]

UFF_TIME, UFF_DIRS = 17, {1: "X", 2: "Y", 3: "Z", 4: "RX", 5: "RY", 6: "RZ"}
CUT = "export the run again (or copy the whole file: it is cut short)"


@dataclass(frozen=True)
class Channel:
    """One recorded channel of a lab export.

    Attributes
    ----------
    names : tuple of str
        The names it answers to, the first shown in messages.
    values : ndarray of float, shape (n,)
        Samples in `unit`.
    t0, dt : float
        Time of the first sample and the sample interval (s).
    unit : str or None
        The unit of `values` as the file defines it ('g', 'm/s^2', 'N', 'V', ...), None when it gives none.
    quantity : str or None
        The quantity the file gives ('acceleration', 'force', ...), None when it gives none.
    """

    names: tuple[str, ...]
    values: NDArray[np.float64]
    t0: float
    dt: float
    unit: str | None = None
    quantity: str | None = None


def lab_channels(path: Path, fmt: str) -> list[Channel]:
    """Every channel of the lab export `path`, of format 'UFF 58', 'TDMS' or 'Test.Lab MAT'."""
    return {"UFF 58": _uff, "TDMS": _tdms, "Test.Lab MAT": _testlab}[fmt](path)


def _interval(dt: object, path: Path, name: str, field: str) -> float:
    """The sample interval (s), checked to be a positive number."""
    try:
        value = float(dt)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        fail(path, f"channel {name!r} has a sample interval of {dt!r} s ({field})",
             "export the record with its sample interval (1 / the sample rate)")
    return value


def _uff(path: Path) -> list[Channel]:
    """The time records (data-set 58) of a UFF file, with data set 164's units."""
    import pyuff

    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions for malformed files
        fail(path, f"cannot be read as a universal file ({type(exc).__name__}: {exc})",
             "export the run as UFF 58 time records (one data-set 58 per channel)")
    sets = sets if isinstance(sets, list) else [sets]
    if not path.read_bytes().rstrip().endswith(b"-1"):  # every data set closes with a '    -1' line
        fail(path, f"the file ends inside a data set (after {len(sets)} whole ones): it is cut short", CUT)
    units164 = next((s for s in sets if s.get("type") == 164), None)
    sets = [s for s in sets if s.get("type") == 58]
    if not sets:
        fail(path, "it holds no data-set 58 (function at a nodal DOF)",
             "export the run's channels as UFF 58 time records")
    out = []
    for s in sets:
        direction = int(s.get("rsp_dir", 0))
        dof = f"{s.get('rsp_node')}:{'+' if direction >= 0 else '-'}{UFF_DIRS.get(abs(direction), '')}"
        name = str(s.get("id1", "")).strip()
        shown = name if name and name != "NONE" else dof
        if s.get("abscissa_spec_data_type") not in (0, 1, UFF_TIME) or not s.get("abscissa_spacing"):
            fail(path, f"record {shown!r} is not an evenly sampled time record (abscissa type "
                 f"{s.get('abscissa_spec_data_type')}, spacing {s.get('abscissa_spacing')})",
                 "export the time records of the run, not spectra or FRFs")
        data = np.asarray(s["data"])
        if np.iscomplexobj(data):
            fail(path, f"record {shown!r} holds complex values (a spectrum)", "export the time records of the run")
        if s.get("num_pts") and data.size < int(s["num_pts"]):
            fail(path, f"record {shown!r} holds {data.size} of its {int(s['num_pts'])} values: the file is cut short",
                 CUT)
        dt = _interval(s.get("abscissa_inc"), path, shown, "abscissa_inc") * \
            _time_scale(s.get("abscissa_axis_units_lab"), path, shown)
        scale, unit, quantity, _ = uff_unit(s, units164, path, shown)
        out.append(Channel((name, dof) if name and name != "NONE" else (dof,), data.astype(np.float64) * scale,
                           float(s.get("abscissa_min", 0.0)), dt, unit, quantity))
    return out


def _tdms_cut(path: Path) -> str | None:
    """How a TDMS file is cut short (a segment announced past the file's end), None when whole."""
    raw = path.read_bytes()
    pos, k = 0, 0
    while pos + 28 <= len(raw) and raw[pos:pos + 4] in (b"TDSm", b"TDSh"):
        toc = struct.unpack("<I", raw[pos + 4:pos + 8])[0]
        end = ">" if toc & (1 << 6) else "<"
        nxt = struct.unpack(end + "Q", raw[pos + 12:pos + 20])[0]
        if nxt == 0xFFFFFFFFFFFFFFFF or pos + 28 + nxt > len(raw):
            return f"its segment {k + 1} announces {nxt} bytes but the file ends {len(raw) - pos - 28} bytes after " \
                   "its lead-in"
        pos, k = pos + 28 + nxt, k + 1
    return None


def _tdms(path: Path) -> list[Channel]:
    """The waveform channels of an NI TDMS file (npTDMS)."""
    import logging

    from nptdms import TdmsFile

    log = logging.getLogger("nptdms")
    level, log.level = log.level, logging.ERROR  # a short last segment is said below, in one sentence
    try:
        tdms = TdmsFile.read(str(path))
    except Exception as exc:  # npTDMS raises ValueError, KeyError, ... for malformed files
        fail(path, f"cannot be read as a TDMS file ({type(exc).__name__}: {exc})", "save the run with NI's TDMS writer")
    finally:
        log.setLevel(level)
    cut = _tdms_cut(path)
    if cut:
        fail(path, f"{cut}: the file is cut short", CUT)
    out = []
    for group in tdms.groups():
        for ch in group.channels():
            props = ch.properties
            name = f"{group.name}/{ch.name}"
            if "wf_increment" not in props:
                fail(path, f"channel {name!r} has no wf_increment (the sample interval)",
                     "save the channels as waveforms (wf_increment, wf_start_offset)")
            out.append(Channel((ch.name, name), np.asarray(ch[:], dtype=np.float64),
                               float(props.get("wf_start_offset", 0.0)),
                               _interval(props["wf_increment"], path, name, "wf_increment"),
                               label(props.get("unit_string"))))
    return out


def _testlab(path: Path) -> list[Channel]:
    """The signals of a Simcenter Test.Lab MATLAB export (scipy.io), in the unit its quantity defines."""
    import scipy.io  # here: the workflow imports jointcal.io to name its jobs, every Snakemake run and stage

    try:
        mat = scipy.io.loadmat(path, simplify_cells=True)
    except (OSError, ValueError) as exc:  # a file cut short: 'could not read bytes'
        fail(path, f"cannot be read whole as a MATLAB file ({exc}): it is cut short or damaged", CUT)
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
        if "number_of_values" in x and values.shape[0] < int(x["number_of_values"]):
            fail(path, f"struct {var!r} holds {values.shape[0]} of its {int(x['number_of_values'])} values "
                 "(x_values.number_of_values): the file is cut short", CUT)
        names = (sig.get("function_record") or {}).get("name", var)
        names = [names] if isinstance(names, str) else [str(n) for n in np.atleast_1d(names)]
        quantities = y.get("quantity") or {}
        quantities = quantities if isinstance(quantities, list) else [quantities] * values.shape[1]
        xq = x.get("quantity") or {}
        scale = _time_scale(xq.get("unit") or xq.get("label"), path, var)
        dt = _interval(x["increment"], path, var, "x_values.increment") * scale
        for j in range(values.shape[1]):
            aliases = (names[j],) if j < len(names) else ()
            aliases += (var,) if values.shape[1] == 1 else (f"{var}:{j + 1}",)
            unit, quantity, _ = testlab_unit(quantities[j] if j < len(quantities) else {}, path, aliases[0])
            out.append(Channel(aliases, values[:, j], float(x["start_value"]), dt, unit, quantity))
    return out


def _time_scale(unit: object, path: Path, name: str) -> float:
    """Seconds per unit of a time axis's label (1 when unlabelled or labelled 'Time')."""
    text = label(unit)
    if text is None or text.lower() == "time":
        return 1.0
    known = unit_size(text)
    if known is None or known[0] != "time":
        fail(path, f"the time axis of {name!r} is in {text!r}, not a time unit", "export the signals against time")
    return known[2]

