"""One backbone whatever the sweep: force- and voltage-driven virtual rigs with a second mode.

A jointed 100 Hz beam with a linear 230 Hz mode at the driving point, on an open-loop shaker
(`tests/_rigs.py`), read by the modal stage: each run's (q_in, f_res_hz, zeta_res) against the
truth's curve at its own q_in (the structure's first-harmonic balance for a force, the coupled
rig's pole for a voltage), and q_in against the amplitude the mode reached. The full matrix
(eta 0.5-500, up and down, three seeds) is tests/benchmarks/accept_backbone.py; here a chirp at
eta 5 that crosses both modes, an impulse-like one at eta 500 and a slow sweep at eta 0.5, with
2% noise, at two levels.
"""
from __future__ import annotations

import numpy as np
import pytest

from tests._support import rigs as _rigs


@pytest.mark.parametrize("ref, eta, direction", [("voltage", 5.0, "up"), ("force", 500.0, "down"),
                                                 ("voltage", 500.0, "up"), ("force", 0.5, "up")])
def test_read_outs_lie_on_the_truths_backbone(tmp_path, ref, eta, direction):
    levels = _rigs.levels_V()
    _rigs.campaign(tmp_path / "c", tmp_path / "t.json", ref=ref, eta=eta, direction=direction, seed=2,
                   levels=[levels[0], levels[2]])
    r = _rigs.read_out(tmp_path / "c", tmp_path / "t.json", ref)
    print("\n" + r[["method", "eta", "q_in", "f_err", "zeta_err", "q_err", "q_peak_err"]].to_string())
    assert (r["method"] == "sweep_fit").all() and (r["flags"] == "").all()
    assert r["eta"].min() > 0.2 * eta
    assert np.abs(r["f_err"]).max() < 1e-3
    assert np.abs(r["zeta_err"]).max() < 0.05
    assert np.abs(r["q_err"]).max() < 0.03
    assert r["q_in"].iloc[1] > 2 * r["q_in"].iloc[0]  # the levels reach different amplitudes
