"""The modal read-out of dwell and ring-down runs (jointcal.measure.testkinds) through `campaign_modal`, on a
linear mode's closed-form records: every run's points in one backbone table, one modal row per run."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io import ingest_campaign, read_run
from jointcal.measure.campaign import campaign_modal
from jointcal.measure.scatter import scatter
from jointcal.measure.testkinds.read import BACKBONE_COLUMNS, backbone_table
from jointcal.measure.testkinds.ringdown import SE_COLUMNS
from tests._support.kinds_records import FN, ZETA, dwell_row, kinds_campaign, linear_dwell

FREQS = (19.3, 19.9, 20.2, 20.5, 21.1)


@pytest.fixture(scope="module")
def modal(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kinds")
    rng = np.random.default_rng(5)
    recs = {f"d{i}": linear_dwell(512.0, f, 0.5, 10.0, 6.0, noise=0.002, rng=rng) for i, f in enumerate(FREQS)}
    recs["r1"] = linear_dwell(512.0, 20.3, 0.5, 4.0, 6.0, noise=0.002, rng=rng)
    rows = [dwell_row(f"d{i}", f, i + 1) for i, f in enumerate(FREQS)] + [dwell_row("r1", 0, 9, test="ringdown")]
    kinds_campaign(folder, rows, recs)
    runs = ingest_campaign(folder)
    points: list = []
    out, frf, _ = campaign_modal(runs, lambda r: (None, {}, read_run(folder / r["file"], r)), {}, points=points)
    table = pd.DataFrame(out)
    return table, points, backbone_table(table, points)


def test_each_run_keeps_one_modal_row_read_at_the_mode(modal):
    table, _, _ = modal
    assert list(table["run_id"]) == [f"d{i}" for i in range(5)] + ["r1"]
    assert set(table["mode"]) == {"m20"} and (table["flags"] == "").all()
    assert list(table["f_res_method"]) == ["dwell"] * 5 + ["ringdown"]
    assert np.abs(table["f_res_hz"] / FN - 1).max() < 5e-4 and np.abs(table["zeta_res"] / ZETA - 1).max() < 0.02
    d = table.iloc[0]
    assert abs(d["f_dwell_quad_hz"] / FN - 1) < 5e-4 and abs(d["zeta_dwell_quad"] / ZETA - 1) < 0.02


def test_the_backbone_holds_every_dwell_point_and_every_ring_down_window(modal):
    table, points, bb = modal
    assert list(bb.columns) == BACKBONE_COLUMNS + list(SE_COLUMNS) and len(bb) == len(points)
    assert (bb["test"] == "dwell").sum() == 5
    assert bb.loc[bb["test"] == "dwell", list(SE_COLUMNS)].isna().all().all()  # a window's length and errors only
    assert (bb.loc[bb["test"] == "ringdown", list(SE_COLUMNS)] > 0).all().all()
    assert list(backbone_table(table, []).columns) == BACKBONE_COLUMNS  # without windows (sweeps): the six
    rd = bb[bb["test"] == "ringdown"]
    assert set(rd["run_id"]) == {f"d{i}" for i in range(5)} | {"r1"}  # the dwells' own ring-downs too
    # a linear mode: the 0.1% / 3% on every window, over more than a decade of amplitude
    assert np.abs(rd["f_hz"] / FN - 1).max() < 1e-3 and np.abs(rd["zeta"] / ZETA - 1).max() < 0.03
    r1 = rd[rd["run_id"] == "r1"]
    assert np.log10(r1["q_in"].max() / r1["q_in"].min()) > 1.0
    assert table.set_index("run_id").loc["r1", "q_in"] == r1["q_in"].max()


def test_a_sweep_row_gives_its_one_point():
    modal = pd.DataFrame({"run_id": ["s1", "s2"], "mode": ["m20", "m20"], "q_in": [1e-3, 2e-3],
                          "f_res_hz": [20.0, 19.9], "zeta_res": [0.02, 0.021], "f_res_method": ["sweep_fit"] * 2,
                          "flags": ["", "level;unusable"]})
    bb = backbone_table(modal, [])
    assert bb.to_dict("records") == [{"run_id": "s1", "mode": "m20", "test": "sweep", "q_in": 1e-3, "f_hz": 20.0,
                                      "zeta": 0.02}]
    # no usable run at all (ring-downs recorded too short to read: no read-out columns): an empty table
    none = pd.DataFrame({"run_id": ["r1"], "mode": ["m20"], "flags": ["no_decay;unusable"]})
    assert list(backbone_table(none, []).columns) == BACKBONE_COLUMNS and backbone_table(none, []).empty


def test_dwells_and_ring_downs_are_no_repeats_in_the_scatter(modal):
    table, _, _ = modal
    assert len(table) == 6 and set(table["level_V"]) == {0.5}  # six runs at one level, none a repeat
    sc = scatter(table)
    assert not (sc["source"] == "repeats").any() and sc["rel_std"].isna().all()


@pytest.mark.parametrize("ref", ["force", "voltage"])
def test_a_decay_with_the_shaker_left_on_is_not_read_as_the_structures_backbone(tmp_path, ref):
    # the beam of tests/_support/rigs.py dwelt at resonance, then its voltage cut. With a force reference the gauge
    # goes on reading the armature's reaction: the decay rings at the coupled rig's pole, 2.4% below the structure's
    # (tests/benchmarks/accept_testkinds.py), so it is flagged and not read; the dwell's own point stands. With a
    # voltage reference the rig's pole is what the whole campaign reads: the decay is read.
    from jointcal.measure.testkinds.read import read_test_run
    from jointcal.synth import generate
    from tests._support import rigs

    f, _ = rigs.truth_curve(ref, rigs.Q_TARGETS[1])
    generate({"seed": 3, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": 0.02},
              "sweep": {"f_start_hz": 0.7 * f, "f_stop_hz": 1.3 * f, "rate_hz_per_s": 1.0},  # (the spec's band)
              "series": [{"level_V": rigs.levels_V()[1], "test": "dwell", "dwell_hz": [round(f, 3)],
                          "dwell_s": 1.5, "decay_s": 2.5}],
              "assemblies": {"beam": rigs.JOINTED_BEAM},
              "rig": {"reference": ref, "shaker": rigs.SMALL_SHAKER, "second_mode": rigs.SECOND_MODE}},
             tmp_path / "c", tmp_path / "t.json")
    row = ingest_campaign(tmp_path / "c").iloc[0].to_dict()
    read = read_test_run(row, read_run(tmp_path / "c" / row["file"], row), ref)
    assert read["point"] is not None and abs(read["point"]["f_hz"] / f - 1) < 1e-3
    if ref == "force":
        assert read["flags"] == ["shaker_on"] and read["windows"] is None
    else:
        assert read["flags"] == [] and len(read["windows"]) >= 1
