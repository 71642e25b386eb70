"""The models validation drives (jointcal.validate.models): the viscous conventions of
ga_best.json."""
from __future__ import annotations

import pytest

from jointcal.units import G
from jointcal.validate import model_from_best

TRUTH = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}
M = 2.65 / G


def test_model_from_best_viscous_conventions():
    best = dict(TRUTH, m=M, viscous="dashpot")
    assert model_from_best(best).zeta_v == TRUTH["zeta_v"]  # the dashpot convention IS MinistackModel's
    const = model_from_best({**best, "viscous": "constant"}, f_ref_hz=2200.0)
    # a dashpot's ratio at f is zeta_v f0 / f: at f_ref it must equal the constant ratio
    assert const.zeta_v * const.f0_hz / 2200.0 == pytest.approx(TRUTH["zeta_v"], rel=1e-12)
    with pytest.raises(ValueError, match="reference frequency"):
        model_from_best({**best, "viscous": "constant"})
