"""The DEAP loop (jointcal.calibrate.ga): its creator classes made once, and an interrupted
run resumed to the same end."""
from __future__ import annotations

import importlib
import warnings

import numpy as np

from jointcal.calibrate import CalibrateSettings, GAOptions, objective, run_ga
from tests._support.modal_tables import M, _data

SPACE = CalibrateSettings().space


def test_reimporting_the_ga_module_does_not_recreate_creator_classes():
    import jointcal.calibrate.ga as ga

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # DEAP warns when a creator class is created twice
        importlib.reload(ga)


def test_interrupted_ga_resumes_to_the_same_end():
    d = _data()
    opt = GAOptions(population=30, offspring=30, generations=8, checkpoint_every=3, seed=5)
    batch = lambda u: objective(SPACE.to_physical(u), d.q, d.f, d.zeta, m=M, valid=SPACE.inside(u))  # noqa: E731
    states = []
    full = run_ga(batch, 6, opt, on_checkpoint=lambda s: states.append(__import__("pickle").dumps(s)))
    at3 = __import__("pickle").loads(states[0])
    assert at3["generation"] == 3
    resumed = run_ga(batch, 6, opt, resume=at3)
    np.testing.assert_array_equal(resumed.best, full.best)
    np.testing.assert_array_equal(resumed.history, full.history)
    assert list(resumed.logbook) == list(full.logbook)
