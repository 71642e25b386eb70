"""emcee in chunks (jointcal.posterior.sampler): the 50-tau stop and an exact resume, an
early stop when tau grows with the chain, and the integrated time against emcee's estimator and the AR(1) closed
form."""
from __future__ import annotations

import pickle

import numpy as np
import pytest

from jointcal.posterior import projected_steps, run_chain


def _gauss(x):
    return -0.5 * np.sum((x / [1.0, 3.0]) ** 2, axis=1)


def test_chain_stops_after_50_tau_and_resumes_exactly():
    x0 = 0.01 * np.random.default_rng(0).standard_normal((16, 2))
    full = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500)
    assert full.converged and full.steps > 50 * full.tau.max() and full.steps < 20000
    saved = []
    part = run_chain(_gauss, x0, seed=3, max_steps=1000, chunk=500, on_chunk=lambda s: saved.append(pickle.dumps(s)))
    assert part.steps == 1000 and not part.converged
    resumed = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, resume=pickle.loads(saved[-1]))
    np.testing.assert_array_equal(resumed.chain, full.chain)  # the chain continues, bit for bit
    np.testing.assert_array_equal(resumed.tau_history, full.tau_history)
    other = run_chain(_gauss, x0, seed=4, max_steps=500, chunk=500)
    assert not np.array_equal(other.chain, full.chain[:500])


def test_chain_whose_tau_grows_stops_early_and_says_why(monkeypatch):
    import jointcal.posterior.sampler as sampler

    x0 = 0.01 * np.random.default_rng(0).standard_normal((16, 2))
    on = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5)
    off = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500)
    assert on.converged and on.stop_reason == "converged" and on.steps == off.steps  # a mixing chain runs on
    # walkers that do not mix: the running tau grows in proportion to the chain (8 steps per 64, as the example
    # campaign's first chunks), so the chain length in units of tau stays flat and 50 tau is never reached
    monkeypatch.setattr(sampler, "_tau", lambda chain, observe: np.full(chain.shape[-1], len(chain) / 8.0))
    saved = []
    res = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5,
                    on_chunk=lambda s: saved.append(pickle.dumps(s)))
    assert not res.converged and res.stop_reason == "projected" and res.projected_steps > 1e9  # flat: no end
    assert res.steps == 3000  # checks 5 and 6 (min_chunks, then once more), not the cap of 40 checks
    again = run_chain(_gauss, x0, seed=3, max_steps=20000, chunk=500, stop_projected=1.5, min_chunks=5,
                      resume=pickle.loads(saved[-2]))  # an interrupted run stops where the whole one did
    np.testing.assert_array_equal(again.chain, res.chain)
    capped = run_chain(_gauss, x0, seed=3, max_steps=4000, chunk=500)  # early stop off: runs to the cap
    assert capped.steps == 4000 and capped.stop_reason == "max_steps"
    # projections: tau settled at 100 steps -> 50 tau = 5000 steps; r = N/tau growing slowly -> far beyond
    assert projected_steps([[1000, 100.0], [2000, 100.0], [3000, 100.0]]) == pytest.approx(5000)
    r1, r3 = 4000 / 495.0, 6000 / 643.0  # equally spaced checks: the least-squares slope is (r3 - r1) / 2000
    assert projected_steps([[4000, 495.0], [5000, 576.0], [6000, 643.0]]) == pytest.approx(
        6000 + (50 - r3) / ((r3 - r1) / 2000), rel=1e-9)


def test_integrated_time_is_emceess_estimator_and_the_ar1_closed_form():
    """The batched autocorrelation time equals emcee's estimator to rounding, and on long AR(1)
    chains the closed form tau = (1 + rho) / (1 - rho) within 10% (the estimator's error, a few %)."""
    import emcee

    from jointcal.posterior.sampler import integrated_time

    rng = np.random.default_rng(7)
    for n_t, rho in ((50, 0.5), (3000, 0.9), (20000, 0.8)):
        x = np.empty((n_t, 32, 3))
        x[0] = rng.normal(size=(32, 3))
        for t in range(1, n_t):
            x[t] = rho * x[t - 1] + np.sqrt(1 - rho**2) * rng.normal(size=(32, 3))
        x[..., 2] = 1e3 * np.exp(x[..., 2])  # scale and skew do not matter
        ours = integrated_time(x)
        np.testing.assert_allclose(ours, emcee.autocorr.integrated_time(x, tol=0), rtol=1e-12)
        if n_t >= 20000:  # long enough for the estimator's own error (a few %) to be small
            np.testing.assert_allclose(ours[:2], (1 + rho) / (1 - rho), rtol=0.1)
