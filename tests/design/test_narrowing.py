"""The predicted narrowing (jointcal.design.narrowing) against draws along the microslip
null manifold (tests/_support/microslip.py): a test below macroslip narrows nothing the data leave free, one past it
identifies the slip force."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.calibrate import CalibrateSettings
from jointcal.design import narrowing, readout
from jointcal.design.evaluate import REPORTED
from jointcal.posterior.identified import identified_table, quantities, unit_jacobian
from tests._support.microslip import M, PARAMS, null_draws, readouts

SPACE = CalibrateSettings().space
NAMES = [*PARAMS, "sigma_f", "sigma_zeta"]


def _setup(q, f, z, S):
    table, info = identified_table(S, NAMES, SPACE, q, f, z, m=M)
    qs = {qt.name: qt for qt in quantities(q, m=M, space=SPACE)}
    u = SPACE.to_unit(S[:, :6])
    grads = np.stack([unit_jacobian(lambda t, qt=qs[n]: (np.log10(qt.fn(t)) if qt.log else qt.fn(t))[:, None],
                                    u, SPACE)[1][:, 0] for n in REPORTED], axis=1)
    t = table.set_index("quantity")
    width = [float(np.log10(t.loc[n, "q95"] / t.loc[n, "q05"]) if t.loc[n, "log"] else t.loc[n, "q95"] - t.loc[n, "q05"])
             for n in REPORTED]
    return info, grads, width, [bool(t.loc[n, "identified"]) for n in REPORTED], np.cov(u, rowvar=False)


def test_a_test_below_macroslip_narrows_nothing_the_data_leave_free():
    q, f, z = readouts()
    S = null_draws(q_max=q.max(), seed=1)
    info, grads, width, ident, cov = _setup(q, f, z, S)
    r = readout(S[:, :6], 5.0, "up", m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    assert not r["macroslip"].any()
    tab, summ = narrowing(S[:, :6], S[:, 6:], info, r, grads, REPORTED, width, ident, cov, SPACE, m=M,
                          targets=("Fs", "KT/k"))
    t = tab.set_index("quantity")
    for name in ("Fs", "KT", "k", "beta", "KT/k"):  # flat along the manifold: one more microslip read-out adds nothing
        assert t.loc[name, "ratio"] == pytest.approx(1.0, abs=1e-3) and t.loc[name, "share_identified"] == 0.0
    assert summ["share_targets"] == 0.0 and t.loc["K0", "ratio"] > 1.0  # it does refine what is identified


def test_a_test_past_macroslip_for_every_draw_identifies_the_slip_force():
    q, f, z = readouts()
    S = null_draws(q_max=q.max(), split=(0.0, 0.3), seed=2)  # macroslip onsets within a factor ~2
    info, grads, width, ident, cov = _setup(q, f, z, S)
    r = readout(S[:, :6], 100.0, "up", m=M, f_lo_hz=700.0, f_hi_hz=2500.0)
    assert r["macroslip"].mean() > 0.95
    tab, summ = narrowing(S[:, :6], S[:, 6:], info, r, grads, REPORTED, width, ident, cov, SPACE, m=M,
                          targets=("Fs", "KT/k"))
    t = tab.set_index("quantity")
    assert summ["share_targets"] > 0.9 and summ["eig_nats"] > 1.0
    assert t.loc["Fs", "ratio"] > 5.0 and t.loc["KT/k", "ratio"] > 5.0
