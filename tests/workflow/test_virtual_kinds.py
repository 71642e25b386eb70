"""A force-driven campaign of every test kind, end to end (opt-in: ``pytest -m acceptance``, about 2 minutes).

The virtual jointed beam of `tests/_support/rigs.py` on its open-loop shaker, the force gauge the reference
(`rigs.kinds_spec`): slow sweeps at three levels, a ring-down cut off from a dwell, five open-loop dwells (one force
level each) with their ring-downs. The truth holds a second, linear mode at 230 Hz (2.36 x the jointed one) that
the one-mode model lacks. Run through the whole workflow with the default config, the discrepancy stage must name
that mode and close the gap, and the design must not quote a search bound as the amplitude to reach.
"""
from __future__ import annotations

import json

import pytest

from jointcal.synth import generate
from tests._support import rigs
from tests._support.workflow import snakemake

pytestmark = pytest.mark.acceptance


def test_a_force_campaign_of_sweeps_ring_downs_and_dwells_runs_end_to_end_and_names_the_second_mode(tmp_path,
                                                                                                   workdir):
    spec, _ = rigs.kinds_spec("force", 1)
    raw, out = tmp_path / "raw", tmp_path / "results"
    generate(spec, raw, tmp_path / "truth.json")
    res = snakemake(workdir, "--cores", "2", "--config", f"raw_data={raw}", f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    unit = next((out / "discrepancy" / "beam").iterdir())  # the one mode, named by its frequency
    d = json.loads((unit / "diagnosis.json").read_text())
    assert d["effect"] == "neighbour_mode" and d["confidence"] == "high"
    ratio = d["recalibrated"]["effect_parameters"]["f_ratio"]
    print(f"\nforce campaign of every kind: {d['effect']} ({d['confidence']}), E {d['metric_before']:.2f} -> "
          f"{d['metric_after']:.2f}, f_ratio {ratio['value']:.3f} {ratio['interval_90']}")
    assert d["metric_after"] < 0.3 * d["metric_before"]
    design = json.loads((out / "design" / "beam" / unit.name / "next_test.json").read_text())
    assert design["recommended"] is None and "until it exceeds" not in design["what_would_identify"]
