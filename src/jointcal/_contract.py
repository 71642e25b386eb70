"""The raw-data contract's names and errors, shared by `jointcal.io` and its helpers.

Private: `jointcal.io` re-exports `CampaignError` and `CampaignWarning`.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Literal, NoReturn

__all__: list[str] = []

Excitation = Literal["base", "force", "voltage"]
OnDataProblem = Literal["error", "flag"]

TIME, RESPONSE = "time_s", "response_accel_g"
# excitation -> reference column; "voltage": the amplifier's drive voltage (only its phase and ratios are used)
REFERENCE: dict[str, str] = {"base": "base_accel_g", "force": "force_lbf", "voltage": "drive_V"}
LEVEL: dict[str, str] = {"base": "level_g", "force": "level_lbf", "voltage": "level_V"}  # manifest column
# a response exported in m/s^2 under this name is converted to g (RESPONSE) on read
RESPONSE_SI, G_SI = "response_accel_m_s2", 9.80665  # m/s^2 per g
TEXT = ("run_id", "assembly", "direction", "file")
POSITIVE = ("f_start_hz", "f_stop_hz", "sweep_rate_hz_per_s", "sample_rate_hz")
FS_RTOL = 1e-3  # allowed relative sample-rate disagreement with the manifest
MIN_CYCLES = 20  # cycles of the lowest drive frequency in each frequency window


class CampaignError(ValueError):
    """A campaign violates the raw-data contract (one sentence: file, problem, fix)."""


class CampaignWarning(UserWarning):
    """A data problem recorded as a flag (``on_data_problem='flag'``)."""


for _cls in (CampaignError, CampaignWarning):
    _cls.__module__ = "jointcal.io"


def fail(where: object, problem: str, fix: str) -> NoReturn:
    """Raise `CampaignError` with the sentence ``"<where>: <problem>; <fix>."``."""
    raise CampaignError(f"{where}: {problem}; {fix}.")


def excitation_of(names: Sequence[str], where: object) -> Excitation:
    """Check a record's column names and return its excitation, 'base', 'force' or 'voltage'.

    Parameters
    ----------
    names : sequence of str
        Column (or MAT variable) names of the record.
    where : object
        The file, named in the message.

    Raises
    ------
    CampaignError
        Unless the names are exactly ``time_s``, one of ``base_accel_g`` /
        ``force_lbf`` / ``drive_V``, and one of ``response_accel_g`` /
        ``response_accel_m_s2`` (in any order).
    """
    names = [str(n) for n in names]
    kinds = [k for k, c in REFERENCE.items() if c in names]
    kind: Excitation = kinds[0] if len(kinds) == 1 else "base"
    response = RESPONSE_SI if RESPONSE_SI in names and RESPONSE not in names else RESPONSE
    want = [TIME, REFERENCE[kind], response]
    fix = f"export the three columns {','.join(want)}"
    found = f"(found: {', '.join(names)})"
    if len(kinds) >= 2:
        fail(where, f"it has {len(kinds)} reference channels {' and '.join(REFERENCE[k] for k in kinds)} {found}",
             "keep the one reference channel of the test (base acceleration, force or drive voltage)")
    missing = [c for c in want if c not in names]
    if missing:
        also = " (or 'force_lbf' / 'drive_V' for a force- / voltage-driven run)" if missing[0] == REFERENCE["base"] else ""
        si = " (or 'response_accel_m_s2' for a response in m/s^2)" if missing[0] == RESPONSE else ""
        fail(where, f"column '{missing[0]}'{also} is missing{si} {found}", fix)
    extra = [c for c in names if c not in want]
    if extra:
        fail(where, f"unexpected column(s) {', '.join(extra)} {found}", fix)
    return kind
