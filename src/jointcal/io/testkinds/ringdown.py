"""ringdown: a free decay, after an impact or a drive cut off (its start found from the drive, else the response)."""
from __future__ import annotations

from .kind import TestKind, lower_direction

__all__ = ["KIND"]

KIND = TestKind("ringdown", (), "a free decay, after an impact or a drive cut off", lower_direction,
                unchecked="not checkable: a ring-down holds no drive over a band", reference_optional=True)
