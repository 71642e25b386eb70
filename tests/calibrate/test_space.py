"""The parameter space (jointcal.calibrate.space): the GA's unit cube and back, a space
grown by an effect's parameters, the joint read by name, bad bounds refused."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.calibrate import PARAMS, UNITS, CalibrateSettings
from tests._support.modal_tables import TABLE_3_2

FIRST = np.array([TABLE_3_2["first"][p] for p in PARAMS])
SPACE = CalibrateSettings().space


def test_space_round_trip_and_scaling():
    p = np.array([FIRST, [1.0, 1e4, -0.95, 1e-4, 1e4, 1e-4], [1e4, 1e8, 0.0, 5.0, 1e8, 0.1]])
    u = SPACE.to_unit(p)
    np.testing.assert_allclose(u[1], 0.0, atol=1e-12)
    np.testing.assert_allclose(u[2], 1.0, atol=1e-12)
    np.testing.assert_allclose(SPACE.to_physical(u), p, rtol=1e-12)
    assert SPACE.x_names == ("log10_Fs", "log10_KT", "chi", "log10_beta", "log10_k", "log10_zeta_v")
    # a decade of Fs is a quarter of its gene range (1..1e4 lbf, log-scaled); chi is linear
    assert SPACE.to_unit([[10.0, 1e6, -0.475, 0.01, 1e6, 0.01]])[0, 0] == pytest.approx(0.25)
    assert SPACE.to_unit([[10.0, 1e6, -0.475, 0.01, 1e6, 0.01]])[0, 2] == pytest.approx(0.5)


def test_space_grows_by_named_parameters_with_their_scaling():
    """ParamSpace.grow appends columns (an effect's), each with its bounds and log/linear scaling;
    the joint's six columns map exactly as before."""
    g = SPACE.grow(["gain", "tau_s"], [0.5, 0.0], [2.0, 4e-4], [True, False])
    assert g.names == (*PARAMS, "gain", "tau_s") and g.ndim == 8
    u = np.array([0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.5, 0.25])
    th = g.to_physical(u)
    np.testing.assert_allclose(th[:6], SPACE.to_physical(u[:6]), rtol=1e-14)
    assert th[6] == pytest.approx(1.0) and th[7] == pytest.approx(1e-4)  # log mid of [0.5, 2]; linear quarter
    np.testing.assert_allclose(g.to_unit(th), u, atol=1e-12)
    with pytest.raises(ValueError, match="log-scaled"):
        SPACE.grow(["tau_s"], [0.0], [1e-4], [True])
    with pytest.raises(ValueError, match="repeat"):
        SPACE.grow(["Fs"], [1.0], [2.0], [True])


def test_a_grown_space_reads_the_joint_by_name():
    """Named access of a grown space: columns, the joint's six, its model and the stuck stiffness and macroslip
    onset, against values written by hand (eq. 3.7: phi_max = Fs (1 + beta) / (KT (beta + (chi+1)/(chi+2))))."""
    g = SPACE.grow(["gain"], [0.5], [2.0], [True], ["-"])
    joint = {"Fs": 280.0, "KT": 1.1e6, "chi": -0.6, "beta": 0.01, "k": 7.0e5, "zeta_v": 0.002}
    th = g.vector({**joint, "gain": 1.12})
    assert g.units == (*(UNITS[p] for p in PARAMS), "-") and g.extra == ("gain",)
    assert g.column(th, "gain") == 1.12 and g.named(th)["zeta_v"] == 0.002
    np.testing.assert_array_equal(g.joint(np.stack([th, th])), [list(joint.values())] * 2)
    assert g.stuck_stiffness(th) == pytest.approx(1.8e6, rel=1e-15)
    c = 0.01 + 0.4 / 1.4
    assert g.phi_max(th) == pytest.approx(280.0 * 1.01 / (1.1e6 * c), rel=1e-12)
    stiffer = g.vector({**joint, "k": 1.4e6, "gain": 1.0})
    model = g.model(np.stack([th, stiffer]), m=0.01)  # batched: fields (P, 1)
    assert model.iwan.Fs.shape == (2, 1) and model.k[1, 0] == 1.4e6 and model.m == 0.01
    assert g.model(th, m=0.01).iwan.chi == -0.6
    with pytest.raises(ValueError, match="missing: gain"):
        g.vector(joint)
    with pytest.raises(KeyError, match="tau_s"):
        g.column(th, "tau_s")


@pytest.mark.parametrize("bounds, match", [
    ({"Fs": [0.0, 10.0]}, "Fs.*lower bound must be > 0"),
    ({"chi": [-1.2, 0.0]}, "chi must lie in"),
    ({"KT": [1e6, 1e5]}, "lower < upper"),
    ({"kappa": [1.0, 2.0]}, r"unknown parameter\(s\) kappa; they are Fs, KT"),
])
def test_space_rejects_bad_bounds(bounds, match):
    with pytest.raises(ValueError, match=match):
        CalibrateSettings.from_config({"bounds": bounds})
