"""The raw-data contract's names and errors, and the one rule that tells a run's excitation.

Public: the stages after ingest read a record's and a table's columns by these names
(`REFERENCE`, `RESPONSE`, `LEVEL`, ...) and raise with `fail`. `jointcal.io` re-exports
`CampaignError`, `CampaignWarning`, `excitation_kind`, `level_column` and `level_unit`.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Literal, NoReturn

from jointcal.units import FOOT_IN, G, G_SI, INCH_M, LBF_N

__all__ = ["Excitation", "OnDataProblem", "TIME", "RESPONSE", "REFERENCE", "LEVEL", "RESPONSE_SI", "TEXT", "START", "REF_FILE",
           "CHANNEL_COLUMNS", "POSITIVE", "QUANTITY", "UNITS", "SI_UNIT", "FS_RTOL", "MIN_CYCLES", "CampaignError",
           "CampaignWarning", "fail", "excitation_kind", "level_column", "level_unit", "excitation_of", "UNUSABLE"]

Excitation = Literal["base", "force", "voltage"]
OnDataProblem = Literal["error", "flag"]

TIME, RESPONSE = "time_s", "response_accel_g"
# excitation -> reference column; "voltage": the amplifier's drive voltage (only its phase and ratios are used)
REFERENCE: dict[str, str] = {"base": "base_accel_g", "force": "force_lbf", "voltage": "drive_V"}
LEVEL: dict[str, str] = {"base": "level_g", "force": "level_lbf", "voltage": "level_V"}  # manifest column
# a response exported in m/s^2 under this name is converted to g (RESPONSE) on read
RESPONSE_SI = "response_accel_m_s2"
TEXT = ("run_id", "assembly", "direction", "file")
START = "sweep_start_s"  # optional manifest column: the sweep's start after the record's first sample (s)
REF_FILE = "reference_file"  # optional manifest column: the lab export holding the reference, when apart
# optional manifest columns naming a lab format's channels: role -> column
CHANNEL_COLUMNS: dict[str, str] = {"reference": "reference_channel", "response": "response_channel"}
POSITIVE = ("f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s", "sample_rate_hz")
# quantity of each channel role: a lab format's unit is checked against it and converted
QUANTITY: dict[str, str] = {"base": "acceleration", "force": "force", "voltage": "voltage"}
# the size of each unit a lab file may use, in the contract's unit of its quantity (g, lbf, V, s)
UNITS: dict[str, dict[str, float]] = {
    "acceleration": {"g": 1.0, "m/s^2": 1.0 / G_SI, "in/s^2": 1.0 / G, "ft/s^2": FOOT_IN / G,
                     "mm/s^2": 1e-3 / G_SI},
    "force": {"lbf": 1.0, "N": 1.0 / LBF_N, "kN": 1e3 / LBF_N},
    "voltage": {"V": 1.0, "mV": 1e-3},
    "time": {"s": 1.0, "ms": 1e-3},
    # read so that a channel of these quantities is named as such (a laser vibrometer), never used as a role
    "velocity": {"m/s": 1.0, "mm/s": 1e-3, "in/s": INCH_M},
    "displacement": {"m": 1.0, "mm": 1e-3, "in": INCH_M},
}
# the SI unit of each quantity, in which Test.Lab stores its values (MKS) and UFF 58 converts with data set 164
SI_UNIT: dict[str, str] = {"acceleration": "m/s^2", "force": "N", "voltage": "V", "time": "s", "velocity": "m/s",
                           "displacement": "m"}
FS_RTOL = 1e-3  # allowed relative sample-rate disagreement with the manifest
MIN_CYCLES = 20  # cycles of the lowest drive frequency in each frequency window
UNUSABLE = "unusable"  # the flag of a run (modal_properties.csv flags) that the later stages leave out


class CampaignError(ValueError):
    """A campaign violates the raw-data contract (one sentence: file, problem, fix)."""


class CampaignWarning(UserWarning):
    """A data problem recorded as a flag (``on_data_problem='flag'``)."""


for _cls in (CampaignError, CampaignWarning):
    _cls.__module__ = "jointcal.io"


def fail(where: object, problem: str, fix: str) -> NoReturn:
    """Raise `CampaignError` with the sentence ``"<where>: <problem>; <fix>."``."""
    raise CampaignError(f"{where}: {problem}; {fix}.")


def excitation_kind(names: Iterable[object], default: Excitation | None = "base") -> Excitation | None:
    """The excitation a set of names shows: 'base', 'force' or 'voltage'.

    The one place that decides it: a record's reference column (``base_accel_g``,
    ``force_lbf``, ``drive_V``) first, else a level column (``level_g``, ``level_lbf``,
    ``level_V``, as a manifest row, runs.csv, modal_properties.csv or a metrics table carry
    it), each looked for in that order.

    Parameters
    ----------
    names : iterable
        Column names of a record or table, or the keys of a row (a mapping iterates its keys).
    default : {'base', 'force', 'voltage'} or None, optional
        The answer when no name is a reference or level column.

    Returns
    -------
    str or None
    """
    names = {str(n) for n in names}
    return next((k for k, c in REFERENCE.items() if c in names), None) or \
        next((k for k, c in LEVEL.items() if c in names), default)


def level_column(names: Iterable[object]) -> str | None:
    """The level column among `names` (``level_g``, ``level_lbf`` or ``level_V``, in that order); None if none."""
    names = {str(n) for n in names}
    return next((c for c in LEVEL.values() if c in names), None)


def level_unit(names: Iterable[object]) -> str:
    """The unit of the level column among `names` ('g', 'lbf' or 'V', `level_column`); '' if there is none."""
    return (level_column(names) or "_").split("_", 1)[1]


def excitation_of(names: Sequence[str], where: object, *, expected: Excitation | None = None,
                  noun: str = "column", others_ok: bool = False) -> Excitation:
    """Check a record's channel names and return its excitation, 'base', 'force' or 'voltage'.

    Parameters
    ----------
    names : sequence of str
        Every column (or MAT variable) name of the record, as the file has them.
    where : object
        The file, named in the message.
    expected : {'base', 'force', 'voltage'}, optional
        The excitation the manifest's level column gives the run: a missing reference
        is then named as that kind's channel.
    noun : str, optional
        What the file calls a channel ('column', 'variable'), used in the message.
    others_ok : bool, optional
        True when names other than the contract's are ignored (MAT files may hold more
        variables); they are still listed in the message.

    Raises
    ------
    CampaignError
        Unless the names hold ``time_s``, one of ``base_accel_g`` / ``force_lbf`` /
        ``drive_V``, and one of ``response_accel_g`` / ``response_accel_m_s2``, and
        (unless `others_ok`) nothing else; in any order.
    """
    names = [str(n) for n in names]
    kinds = [k for k, c in REFERENCE.items() if c in names]
    kind: Excitation = kinds[0] if len(kinds) == 1 else (expected or "base")
    response = RESPONSE_SI if RESPONSE_SI in names and RESPONSE not in names else RESPONSE
    want = [TIME, REFERENCE[kind], response]
    verb = "save the MAT variables" if noun == "variable" else f"export the three {noun}s"
    fix = f"{verb} {','.join(want)}"
    found = f"(the file's {noun}s: {', '.join(names)})" if names else f"(the file has no {noun}s)"
    if len(kinds) >= 2:
        fail(where, f"it has {len(kinds)} reference channels {' and '.join(REFERENCE[k] for k in kinds)} {found}",
             "keep the one reference channel of the test (base acceleration, force or drive voltage)")
    missing = [c for c in want if c not in names]
    if missing:
        also = ""
        if missing[0] == REFERENCE[kind] and expected is None:
            also = " (or 'force_lbf' / 'drive_V' for a force- / voltage-driven run)"
        elif missing[0] == REFERENCE[kind]:
            also = f" (the manifest's {LEVEL[kind]} makes the run {kind}-driven)"
        si = " (or 'response_accel_m_s2' for a response in m/s^2)" if missing[0] == RESPONSE else ""
        fail(where, f"{noun} '{missing[0]}'{also} is missing{si} {found}", fix)
    extra = [c for c in names if c not in want]
    if extra and not others_ok:
        fail(where, f"unexpected {noun}(s) {', '.join(extra)} {found}", fix)
    return kind
