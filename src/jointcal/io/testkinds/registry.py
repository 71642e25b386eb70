"""The registry of test kinds: register, look up by name or by a manifest row, tell swept kinds from the others."""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import pandas as pd

from jointcal.io.contract import fail
from .kind import TestKind

__all__ = ["TEST_KINDS", "TEST", "DEFAULT", "register", "manifest_kind", "run_test_kind", "test_kind",
           "is_swept", "swept_mask", "kind_columns"]

TEST = "test"  # manifest column: the run's test kind
DEFAULT = "sweep"  # the kind of a row without one (the column absent or the cell empty: the contract before kinds)
TEST_KINDS: dict[str, TestKind] = {}


def register(kind: TestKind) -> TestKind:
    """Add a test kind to the registry (the manifest, the checks and the reader then know it)."""
    if not kind.name or kind.name != kind.name.strip().lower():
        raise ValueError(f"test kind name {kind.name!r}: write one lower-case word.")
    TEST_KINDS[kind.name] = kind
    return kind


def manifest_kind(rec: Mapping[str, Any], where: str) -> TestKind:
    """The kind a manifest row names in ``test`` (`DEFAULT` when the column is absent or the cell empty).

    Raises
    ------
    CampaignError
        A ``test`` value that is none of `TEST_KINDS`.
    """
    word = str(rec.get(TEST, "") or "").strip().lower()
    if not word:
        return TEST_KINDS[DEFAULT]
    if word not in TEST_KINDS:
        fail(where, f"test {str(rec[TEST]).strip()!r} is not a test kind of the contract",
             f"write {', '.join(TEST_KINDS)} (empty is {DEFAULT})")
    return TEST_KINDS[word]


def run_test_kind(row: Mapping[str, Any]) -> TestKind:
    """The kind of a checked row (`DEFAULT` when it has no ``test`` or it is empty/NaN)."""
    word = row.get(TEST, "")
    return TEST_KINDS[word if isinstance(word, str) and word in TEST_KINDS else DEFAULT]


def test_kind(row: Mapping[str, Any]) -> str:
    """The kind's name of a checked row (`run_test_kind`'s)."""
    return run_test_kind(row).name


test_kind.__test__ = False  # type: ignore[attr-defined]  # not a pytest test, whatever its name


def is_swept(test: object) -> bool:
    """Whether a ``test`` value (a kind's name; empty, NaN or None: `DEFAULT`) is read as a sweep."""
    return run_test_kind({TEST: test}).swept


def swept_mask(tests: pd.Series) -> pd.Series:
    """`is_swept` of each value of a table's ``test`` column (boolean, same index)."""
    return tests.map(is_swept).astype(bool)


def kind_columns() -> tuple[str, ...]:
    """The manifest columns some kind needs and another does not (a campaign without that kind may leave
    them out of its header)."""
    return tuple(dict.fromkeys(c for k in TEST_KINDS.values() for c in k.needs))
