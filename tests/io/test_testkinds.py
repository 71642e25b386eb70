"""The test-kind registry of the contract (jointcal.io.testkinds): one module per kind, asked instead of its name."""
from __future__ import annotations

import math

import pandas as pd
import pytest

from jointcal.io.testkinds import (DEFAULT, DWELL, SWEEP_ONLY, TEST_KINDS, TestKind, is_swept, kind_columns,
                                   run_test_kind, swept_mask, test_kind)
from jointcal.io.testkinds.kind import lower_direction


def test_the_registry_holds_the_three_kinds_in_order_and_sweep_is_the_default():
    assert list(TEST_KINDS) == ["sweep", "dwell", "ringdown"] and DEFAULT == "sweep"
    assert TEST_KINDS["sweep"].needs == SWEEP_ONLY and TEST_KINDS["dwell"].needs == (DWELL,)
    assert kind_columns() == (*SWEEP_ONLY, DWELL)
    assert [k.swept for k in TEST_KINDS.values()] == [True, False, False]
    assert [k.reference_optional for k in TEST_KINDS.values()] == [False, False, True]


@pytest.mark.parametrize("test, name", [(None, "sweep"), ("", "sweep"), (math.nan, "sweep"), ("dwell", "dwell"),
                                        ("ringdown", "ringdown"), ("a word of no kind", "sweep")])
def test_a_checked_row_without_a_kind_is_a_sweep(test, name):
    row = {} if test is None else {"test": test}
    assert test_kind(row) == name and run_test_kind(row) is TEST_KINDS[name]
    assert is_swept(test) == (name == "sweep")


def test_swept_mask_reads_a_table_column_nan_as_the_default():
    assert swept_mask(pd.Series(["sweep", "dwell", math.nan, "ringdown"])).tolist() == [True, False, True, False]


def test_a_kind_with_no_band_must_say_why_and_its_numbers_are_among_its_needs():
    with pytest.raises(ValueError, match="unchecked"):
        TestKind("impact", (), "a hammer blow", lower_direction)
    with pytest.raises(ValueError, match="numbers"):
        TestKind("impact", (), "a hammer blow", lower_direction, numbers=("hammer_hz",), unchecked="no drive")
