"""A stage's section of the workflow config, checked before its settings are built."""
from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any


def config_section(section: Mapping[str, Any] | None, allowed: Iterable[str], stage: str) -> dict[str, Any]:
    """A copy of the config's ``stage:`` mapping (empty when absent); one sentence for a key that is not a setting."""
    section = dict(section or {})
    unknown = sorted(set(section) - set(allowed))
    if unknown:
        raise ValueError(f"{stage}: unknown key(s) {', '.join(unknown)}")
    return section
