"""The modal stage's tables read for the calibration (jointcal.calibrate.data): unusable
runs left out (and runs flagged at ingest with them), a run without a read-out left out with a note, a bad or
missing table one sentence naming the file, the floor when the pooled scatter is missing."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import CalibrationInputError, read_modal, select_modal
from jointcal.calibrate.data import select_modal
from tests._support.modal_tables import TABLE_3_2, modal_tables, write_tables


def test_unusable_rows_are_left_out_other_flags_kept():
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    modal.loc[0, "flags"] = "low_snr;unusable"
    modal.loc[1, "flags"] = "eta_high"
    modal.loc[0, "q_in"] = np.nan  # an unusable row may hold NaN: never read
    d = select_modal(modal, "first", scatter=scatter)
    assert d.run_id == tuple(modal["run_id"][1:])
    assert "1 of 12 runs" in d.notes[0]


def _break(tmp_path, edit):
    modal_csv, scatter_csv = write_tables(tmp_path, {"first": TABLE_3_2["first"]}, seed=1)
    df = pd.read_csv(modal_csv)
    edit(df)
    df.to_csv(modal_csv, index=False)
    return modal_csv


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.pop("q_in"), "column(s) q_in missing"),
    (lambda d: d.__setitem__("flags", "unusable"), "all 12 runs of assembly 'first' are flagged unusable"),
    # every run unusable and no read-out column at all (the modal stage read nothing, e.g. force-driven dwells with
    # the shaker left on and no sweep): the runs are what to fix, not the table
    (lambda d: [d.__setitem__("flags", "shaker_on;unusable"), *(d.pop(c) for c in ("q_in", "f_res_hz", "zeta_res"))],
     "all 12 runs of assembly 'first' are flagged unusable"),
    (lambda d: d.__setitem__("zeta_res", np.nan), "set calibrate.damping to zeta_phase_resonance"),
    (lambda d: d.__setitem__("assembly", "other"), "no runs of assembly 'first'"),
])
def test_bad_modal_table_is_one_sentence_naming_the_file(tmp_path, edit, message):
    modal_csv = _break(tmp_path, edit)
    with pytest.raises(CalibrationInputError) as err:
        read_modal(modal_csv, "first")
    text = str(err.value)
    assert text.startswith(f"{modal_csv}: ") and message in text and text.endswith(".") and "\n" not in text


def test_a_run_without_a_read_out_is_left_out_with_a_note(tmp_path):
    modal_csv = _break(tmp_path, lambda d: d.loc.__setitem__((3, "f_res_hz"), np.nan))
    d = read_modal(modal_csv, "first")
    assert "first_04_1g_down" not in d.run_id and len(d.run_id) == 11
    assert any("'first_04_1g_down' has no positive q_in, f_res_hz and zeta_res" in n and n.endswith("left out")
               for n in d.notes)


def test_a_voltage_campaign_asked_for_phase_resonance_damping_is_told_which_column_it_has():
    """A voltage-driven run has no phase-resonance damping (the voltage is not a force): the sentence says
    so and names the column to use instead of stopping on the first NaN."""
    modal, _ = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    modal = modal.rename(columns={"level_g": "level_V"}).assign(zeta_phase_resonance=np.nan)
    with pytest.raises(CalibrationInputError) as err:
        select_modal(modal, "first", damping="zeta_phase_resonance")
    text = str(err.value)
    assert "a voltage is not a force" in text and "set calibrate.damping to zeta_res" in text and "\n" not in text


def test_missing_table_names_the_file(tmp_path):
    with pytest.raises(CalibrationInputError, match="nowhere.csv: the file does not exist"):
        read_modal(tmp_path / "nowhere.csv", "first")


def test_missing_or_zero_pooled_scatter_falls_back_to_the_floor():
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=1)
    pooled_f = (scatter["source"] == "pooled") & (scatter["quantity"] == "f_res_hz")
    scatter.loc[pooled_f, "rel_std"] = 0.0
    scatter = scatter[~((scatter["source"] == "pooled") & (scatter["quantity"] == "zeta_res"))]
    d = select_modal(modal, "first", scatter=scatter, floors={"frequency": 3e-4, "damping": 0.02})
    assert d.rel_noise == (3e-4, 0.02)
    assert sum("using the floor" in n for n in d.notes) == 2


def test_level_mistakes_are_left_out_of_the_calibration():
    """A run flagged for its units, level or channels at ingest never enters the fit."""
    modal = pd.DataFrame({"run_id": ["r1", "r2", "r3", "r4"], "assembly": "first", "q_in": [1e-4, 2e-4, 1e-3, 3e-4],
                          "f_res_hz": 2000.0, "zeta_phase_resonance": 0.01, "zeta_res": 0.01,
                          "level_g": [1.0, 1.0, 1.0, 2.0],
                          "flags": ["", "level:base_accel_g", "swapped:base_accel_g;bad_samples",
                                    "clipped:response_accel_g"]})
    data = select_modal(modal, "first")
    assert data.run_id == ("r1",)  # clipped: the peak is missing, damping biased high (see tests/io/test_clipping.py)
