"""The fast model's fits (jointcal.discrepancy.fit): an effect's parameters in the unit
cube and back, a new library effect grows the space with no other change, E of the truth about one on noise at the
scatter."""
import numpy as np

from jointcal.calibrate.space import PARAMS
from jointcal.discrepancy import decide, score_candidates
from jointcal.discrepancy.fit import Objective, candidate, model_at
from jointcal.effects import EFFECTS
from tests._support.envelopes import M, SPACE, TRUTH, _runs


def test_effect_parameters_map_to_the_unit_cube_and_back():
    for name in ("baseline", *EFFECTS):
        c = candidate(name, SPACE, M)
        theta = np.r_[TRUTH, [p.start if p.start != 0 else 0.5 * (p.lo + p.hi) for p in c.effect_params]]
        np.testing.assert_allclose(c.to_physical(c.to_unit(theta)), theta, rtol=1e-12)
        model_at(c, theta, {"sequence": 5})  # every effect builds a model


def test_a_new_library_effect_grows_the_space_and_is_fitted_without_other_changes(monkeypatch):
    """The parameter space grows by an effect's parameters with no code change elsewhere.
    A new entry (a base-channel gain error, the response read against a base that reads b high:
    T_read = T / b) is registered in the library only; the fit's space becomes the six joint columns
    plus b with its bounds and scaling, and the hidden b = 0.9 is recovered and named."""
    from dataclasses import replace as dc_replace
    from jointcal.effects import Effect, EffectParam
    new = Effect("base_gain", (EffectParam("b", "-", 0.5, 2.0, True, 1.0, "base channel reading / true"),),
                 lambda m, v, row: dc_replace(m, sensor_gain=m.sensor_gain / v["b"]), lambda v: "check the base")
    monkeypatch.setitem(EFFECTS, "base_gain", new)
    c = candidate("base_gain", SPACE, M)
    assert c.names == (*PARAMS, "b") and c.grown.ndim == 7 and bool(c.grown.is_log[-1])
    np.testing.assert_allclose(c.to_unit(np.r_[TRUTH, 1.0])[-1], 0.5)  # log scale: 1 is the middle of [0.5, 2]
    runs = _runs("base_gain", [0.9])
    cands = [candidate(n, SPACE, M) for n in ("baseline", "base_gain", "channel_delay")]
    name, conf, ranked, *_ = decide(score_candidates(cands, runs, TRUTH * np.array([1.1, 0.95, 1, 1, 1.05, 1.2]),
                                                 max_nfev=25))
    assert name == "base_gain" and abs(ranked[0].fit.theta[6] / 0.9 - 1) < 0.03


def test_E_of_the_truth_is_about_one_on_noise_at_the_scatter():
    runs = _runs()
    E = Objective(candidate("baseline", SPACE, M), runs).E(TRUTH)
    assert 0.8 < E < 1.2  # noise of exactly the scatter: E = 1 within its sampling spread (1280 frames)


def test_a_refreshing_fit_tries_its_effect_starts_and_grid(monkeypatch):
    """A fit with refresh (every stage fit) starts the effect values theta0 leaves out from their start, spread
    points and the best point of their grid (`EffectParam.grid`), and refits from its optimum alone; the grid's
    best point is one batched evaluation. (The refreshing path once passed the completed vector on: the start
    value alone was tried.)"""
    from dataclasses import replace as dc_replace
    from jointcal.discrepancy import fit as fit_module
    from jointcal.effects import Effect, EffectParam
    new = Effect("base_gain", (EffectParam("b", "-", 0.5, 2.0, True, 1.0, "base channel reading / true", grid=9),),
                 lambda m, v, row: dc_replace(m, sensor_gain=m.sensor_gain / v["b"]), lambda v: "check the base")
    monkeypatch.setitem(EFFECTS, "base_gain", new)
    c = candidate("base_gain", SPACE, M)
    runs = _runs("base_gain", [0.6])
    x0s = []
    real = fit_module.least_squares

    def spy(fun, x0, **kw):
        x0s.append(np.array(x0, float))
        return real(fun, x0, **kw)

    monkeypatch.setattr(fit_module, "least_squares", spy)
    f = Objective(c, runs).fit(TRUTH, starts=3, max_nfev=15, refresh=1)
    b0 = [x[-1] for x in x0s]
    # the first fit: the start (b = 1, u 0.5), the spread points (u 0.15, 0.85), the grid's best (u = 1/8: b 0.6
    # is u 0.132); then the refit from its optimum
    assert len(x0s) == 5 and np.allclose(b0[:3], [0.5, 0.15, 0.85], atol=1e-5)
    assert abs(b0[3] - 0.125) < 1e-3 and abs(f.theta[6] / 0.6 - 1) < 0.03
