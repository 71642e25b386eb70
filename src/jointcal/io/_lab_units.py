"""The unit of a lab export's channel as its format defines it, and its label checked against it.

Private: the readers of `jointcal.io._lab_channels` call `testlab_unit` and `uff_unit`.

* Simcenter Test.Lab MATLAB export: the values are stored in SI ("Data saved by Test.Lab
  in MKS", the quantity's ``info``), of the dimensions its ``quantity_terms`` give
  (exponents of LENGTH, MASS, TIME, CURRENT, ...); ``label`` is only the unit shown, and
  ``unit_transformation.factor`` converts the SI values to it (0.10197 for 'g').
* UFF 58: the ordinate's unit exponents (length, force; time is implicit) and its
  specific data type (12 acceleration, 11 velocity, 8 displacement, 9 and 13 force)
  give the dimensions, in the file's unit system: data set 164's factors convert it to
  SI (divide by length^e_length x force^e_force); a file without data set 164 is taken
  in SI. All exponents 0 say nothing (pyuff's default): the units label is then read;
  without a label, a file with data set 164 gives the data type's dimensions in its
  system (exponents 0 on an acceleration are a writer's default, not a dimension).

A label that names a unit of other dimensions than the stored quantity, or of another
size than the stored unit, is named (`fail`): one of the two is wrong, and the reader
cannot tell which.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from jointcal.io.contract import SI_UNIT, UNITS, fail

__all__ = ["testlab_unit", "uff_unit", "unit_size", "label"]

# exponents of (LENGTH, MASS, TIME, CURRENT) -> quantity
TESTLAB_DIMS = {(1, 0, -2, 0): "acceleration", (1, 0, -1, 0): "velocity", (1, 0, 0, 0): "displacement",
                (1, 1, -2, 0): "force", (2, 1, -3, -1): "voltage", (0, 0, 1, 0): "time"}
TESTLAB_TERMS = ("LENGTH", "MASS", "TIME", "CURRENT")
# UFF specific data type -> quantity, and the (length, force) exponents of that quantity
UFF_QUANTITY = {8: "displacement", 9: "force", 11: "velocity", 12: "acceleration", 13: "force", 15: "pressure"}
UFF_EXPONENTS = {"displacement": (1, 0), "velocity": (1, 0), "acceleration": (1, 0), "force": (0, 1)}
QUANTITY_WORDS = ("acceleration", "force", "voltage", "time", "displacement", "velocity", "pressure")
REL = 1e-4  # a label's size and the stored unit's agree within this (Test.Lab writes 15 digits)


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
    return str(text).translate(str.maketrans("", "", " \t^*")).replace("²", "2").lower().replace("sec", "s")


def label(text: object) -> str | None:
    """A unit or quantity label, None when empty or 'NONE' (pyuff's placeholder)."""
    text = str(text).strip() if text is not None else ""
    return None if not text or text.upper() == "NONE" else text


def _check_label(shown: str | None, quantity: str, unit: str, said_by: str, where: object, name: str, *,
                 size: bool = True) -> None:
    """Name a label of other dimensions than the stored unit (`unit`, of `quantity`), or (`size`) of another size."""
    known = unit_size(shown) if shown else None
    if known is None:
        return
    q, _, shown_size = known
    if q != quantity:
        fail(where, f"channel {name!r} is labelled {shown!r}, {_a(q)}, but {said_by} make its values {_a(quantity)} "
             f"in {unit}", "correct the channel's label or its quantity in the export")
    if size and abs(shown_size / UNITS[quantity][unit] - 1) > REL:
        fail(where, f"channel {name!r} is labelled {shown!r}, but {said_by} make its values {unit}",
             "correct the channel's label or its unit in the export (one of them is wrong)")


def testlab_unit(q: Mapping[str, Any], where: object, name: str) -> tuple[str | None, str | None, str]:
    """(unit, quantity, how said) of a Test.Lab ``quantity`` struct.

    Parameters
    ----------
    q : mapping
        ``y_values.quantity`` (or ``x_values.quantity``) of one channel.
    where, name : object, str
        The file and the channel, named in messages.

    Returns
    -------
    unit : str or None
        The unit the stored values are in (the SI unit of its ``quantity_terms`` when
        they are given), None when the struct says none.
    quantity : str or None
        'acceleration', 'velocity', 'force', ... or None.
    said : str
        What gave the unit, for messages.
    """
    shown = label(q.get("label"))
    terms = q.get("quantity_terms")
    word = shown.lower() if shown and shown.lower() in QUANTITY_WORDS else None
    if terms is not None:  # Test.Lab: values in MKS of these dimensions
        terms = terms if isinstance(terms, list) else [terms]
        exps = {str(t.get("quantity", "")).upper(): float(t.get("num", 0)) / float(t.get("den", 1) or 1)
                for t in terms if isinstance(t, Mapping)}
        dims = tuple(int(exps.get(k, 0)) for k in TESTLAB_TERMS)
        if not any(exps.values()):
            return None, word, "none"
        quantity = TESTLAB_DIMS.get(dims)
        if quantity is None:
            fail(where, f"channel {name!r} holds a quantity of dimensions {dict(zip(TESTLAB_TERMS, dims))} "
                 f"(its quantity_terms), which jointcal does not read", "export the channel as an acceleration, a "
                 "force or a voltage")
        unit = SI_UNIT[quantity]
        said = "its quantity_terms (stored in MKS)"
        _check_label(shown, quantity, unit, said, where, name, size=False)  # the label is the unit shown
        factor = (q.get("unit_transformation") or {}).get("factor")
        known = unit_size(shown) if shown else None
        if known is not None and factor is not None and \
                abs(float(factor) * known[2] / UNITS[quantity][unit] - 1) > REL:
            fail(where, f"channel {name!r} is labelled {shown!r}, but its unit_transformation.factor {factor:g} "
                 f"does not convert {unit} (its MKS values) to {shown!r}",
                 "correct the label or the factor in the export")
        return unit, quantity, said
    transform = q.get("unit_transformation")
    if transform is not None and shown and unit_size(shown):  # Test.Lab without quantity_terms: still MKS
        quantity = unit_size(shown)[0]
        return SI_UNIT[quantity], quantity, f"its label {shown!r} (stored in MKS)"
    unit = label(q.get("unit")) or (shown if shown and unit_size(shown) else None)
    return unit, word, "its unit"


def uff_unit(s: Mapping[str, Any], units164: Mapping[str, Any] | None, where: object,
             name: str) -> tuple[float, str | None, str | None, str]:
    """(scale to the stored unit, unit, quantity, how said) of a UFF 58 ordinate.

    Parameters
    ----------
    s : mapping
        The data set 58 as pyuff reads it.
    units164 : mapping or None
        The file's data set 164 (pyuff), None when it has none (SI is then assumed).
    where, name : object, str
        The file and the record, named in messages.

    Returns
    -------
    scale : float
        Multiply the file's values by it to have them in `unit` (1 unless the unit
        exponents and data set 164 give a non-SI system, converted to SI).
    unit, quantity : str or None
        The unit of the scaled values and the record's quantity, None when not said.
    said : str
        What gave the unit, for messages.
    """
    quantity = UFF_QUANTITY.get(int(s.get("ordinate_spec_data_type", 0) or 0))
    shown = label(s.get("ordinate_axis_units_lab"))
    exps = (int(s.get("ordinate_len_unit_exp", 0) or 0), int(s.get("ordinate_force_unit_exp", 0) or 0))
    said = "its unit exponents and data set 164" if units164 else \
        "its unit exponents (SI: the file has no data set 164)"
    if exps == (0, 0) and (shown or units164 is None or quantity not in UFF_EXPONENTS):
        return 1.0, shown, quantity, "its units label"  # the exponents say nothing: the label is the unit
    if exps == (0, 0):  # no label, exponents 0, but a unit system: the data type's dimensions in it
        exps, said = UFF_EXPONENTS[quantity], "its data type and data set 164 (its unit exponents are 0)"
    if quantity is None and exps == (1, 0):  # a general record in length / time^k: the contract reads accelerations
        quantity = "acceleration"
    if quantity not in UFF_EXPONENTS or UFF_EXPONENTS[quantity] != exps:
        fail(where, f"record {name!r} has the unit exponents length {exps[0]}, force {exps[1]}, which are not "
             f"those of {_a(quantity) if quantity else 'a quantity jointcal reads'} (its specific data type "
             f"{s.get('ordinate_spec_data_type')})", "correct the record's data type or unit exponents in the export")
    length = float(units164.get("length", 1.0)) if units164 else 1.0
    force = float(units164.get("force", 1.0)) if units164 else 1.0
    if length <= 0 or force <= 0:
        fail(where, f"its data set 164 gives the unit factors length {length:g}, force {force:g}",
             "export the file with its unit system's factors (SI: 1 and 1)")
    unit = SI_UNIT[quantity]
    _check_label(shown, quantity, unit, said, where, name)
    return 1.0 / (length ** exps[0] * force ** exps[1]), unit, quantity, said


def _a(word: str) -> str:
    return f"{'an' if word[0] in 'aeiou' else 'a'} {word}"
