"""The virtual lab's dwells and ring-downs (jointcal.synth.dwell, jointcal.synth.ringdown) through ingest and the
modal stage's read-out, against the exact joint's first-harmonic balance: the Ministack (base-driven, closed-loop ripple 1%, distortion
0.3%/0.2%, noise 0.1% of each channel's rms, 24-bit DAQ with its anti-alias filter)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal.io import ingest_campaign, read_run
from jointcal.measure.campaign import campaign_modal
from jointcal.measure.testkinds.read import backbone_table
from jointcal.models import harmonic_balance
from jointcal.synth import DEFAULT_SPEC, generate
from jointcal.units import G

FIRST = DEFAULT_SPEC["assemblies"]["first"]
JOINT = (FIRST["Fs"], FIRST["KT"], FIRST["chi"], FIRST["beta"], FIRST["k"], DEFAULT_SPEC["slug_weight_lbf"] / G,
         FIRST["zeta_v"])
SPEC = {"seed": 11, "assemblies": {"first": FIRST},
        "series": [{"level_g": 2.0, "test": "ringdown", "dwell_hz": [2180.0], "dwell_s": 0.3, "decay_s": 1.2},
                   {"level_g": 2.0, "test": "dwell", "dwell_hz": [2140.0, 2160.0, 2180.0, 2200.0, 2220.0],
                    "dwell_s": 0.4, "decay_s": 1.2}],
        "measurement": {"noise_fraction": 1e-3, "dc_offset_g": 0.0}}


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    folder = tmp_path_factory.mktemp("steady")
    generate(SPEC, folder / "campaign", folder / "truth.json")
    runs = ingest_campaign(folder / "campaign")
    points: list = []
    rows, _, _ = campaign_modal(runs, lambda r: (None, {}, read_run(folder / "campaign" / r["file"], r)), {},
                                points=points)
    table = pd.DataFrame(rows)
    return runs, table, backbone_table(table, points)


def test_the_virtual_lab_writes_dwells_and_ring_downs_in_the_contract(lab):
    runs, table, _ = lab
    assert list(runs["test"]) == ["ringdown"] + ["dwell"] * 5 and runs["f_start_hz"].isna().all()
    assert np.allclose(runs["f_first_hz"][1:], SPEC["series"][1]["dwell_hz"], rtol=1e-6)
    assert set(table["mode"]) == {table["mode"].iloc[0]} and not table["flags"].str.contains("unusable").any()


def test_virtual_dwells_read_the_harmonic_balance_at_the_amplitude_reached(lab):
    _, table, bb = lab
    d = table[table["f_res_method"] == "dwell"].iloc[0]
    f, z = harmonic_balance(np.array([d["q_dwell_quad_in"]]), *JOINT)
    assert abs(d["f_dwell_quad_hz"] / f[0] - 1) < 5e-4 and abs(d["zeta_dwell_quad"] / z[0] - 1) < 0.02
    pts = bb[bb["test"] == "dwell"]
    f_p, _ = harmonic_balance(pts["q_in"].to_numpy(), *JOINT)
    assert len(pts) == 5 and np.abs(pts["f_hz"] / f_p - 1).max() < 5e-4  # the base's modal constant is -G exactly


def test_virtual_ring_downs_read_the_harmonic_balance_backbone(lab):
    # issue 31's line on every window of the six decays (the ring-down and the five dwells' own), each read over
    # 1.5 decades or more (here 1.66-1.96; over six seeds 1.66-2.12 decades, f within 0.062%, zeta within 2.9%)
    _, _, bb = lab
    rd = bb[bb["test"] == "ringdown"]
    f, z = harmonic_balance(rd["q_in"].to_numpy(), *JOINT)
    assert np.abs(rd["f_hz"] / f - 1).max() < 1e-3 and np.abs(rd["zeta"] / z - 1).max() < 0.03
    assert min(np.log10(g["q_in"].max() / g["q_in"].min()) for _, g in rd.groupby("run_id")) > 1.5
