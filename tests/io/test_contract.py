"""The contract's one excitation rule and its level column (jointcal.io.contract)."""
import pandas as pd
import pytest

from jointcal.io import excitation_kind, level_column, level_unit


@pytest.mark.parametrize("names, kind", [
    (["time_s", "base_accel_g", "response_accel_g"], "base"),
    (["time_s", "force_lbf", "response_accel_m_s2"], "force"),
    (["drive_V", "response_accel_g"], "voltage"),
    (["run_id", "level_g"], "base"),
    (["run_id", "level_lbf", "f_res_hz"], "force"),
    (["level_V"], "voltage"),
    (["force_lbf", "level_g"], "force"),  # a record's reference channel decides before a level column
    ([], "base"),
])
def test_one_excitation_rule(names, kind):
    assert excitation_kind(names) == kind
    assert excitation_kind(dict.fromkeys(names, 1.0)) == kind  # a row's keys


def test_level_column_and_no_default():
    assert level_column(["run_id", "level_V"]) == "level_V"
    assert level_column(pd.DataFrame(columns=["level_lbf", "q_in"]).columns) == "level_lbf"
    assert level_column(["run_id"]) is None
    assert [level_unit(["q_in", c]) for c in ("level_g", "level_lbf", "level_V")] == ["g", "lbf", "V"]
    assert level_unit({"run_id": "a"}) == ""  # a row's keys, no level
    assert excitation_kind(["run_id"], None) is None
