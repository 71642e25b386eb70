"""Separated modes of the draws (jointcal.posterior.modes), with a known answer: a bimodal
sample's weights and locations, modes along a diagonal, a single mode never split."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.posterior import find_modes, mode_labels, modes_text
from tests._support.samples import _bimodal


def test_modes_of_a_bimodal_sample_have_the_known_weights_and_locations():
    x, second = _bimodal()
    m = find_modes(x, [f"p{i}" for i in range(8)]).set_index(["mode", "param"])
    assert m.index.get_level_values("mode").max() == 1
    # weights within 0.02 of 0.7 / 0.3 (binomial sd 0.004 at n = 12000; the cut misassigns < 0.1% at 6 sd)
    assert m.loc[(0, "p0"), "weight"] == pytest.approx(0.7, abs=0.02)
    assert m.loc[(1, "p0"), "weight"] == pytest.approx(0.3, abs=0.02)
    # each mode's median sits at its centre (sd of a median of >= 3600 unit-normal draws: 0.02)
    assert m.loc[(0, "p0"), "median"] == pytest.approx(0.0, abs=0.1)
    assert m.loc[(1, "p0"), "median"] == pytest.approx(6.0, abs=0.1)
    assert np.mean(mode_labels(x)[second] == 1) > 0.99
    text = modes_text(find_modes(x, [f"p{i}" for i in range(8)]), ["p0"], converged=False)
    assert "MULTIMODAL (2 separated modes" in text and "walkers started" in text


def test_modes_along_a_diagonal_are_found_and_single_modes_are_not_split():
    rng = np.random.default_rng(2)
    x = rng.standard_normal((12000, 8))
    second = rng.random(12000) < 0.4
    x[second, :2] += 4.0  # separated only along p0 + p1 (2.8 sd in each marginal)
    assert np.bincount(mode_labels(x)).tolist() == pytest.approx([12000 - second.sum(), second.sum()], abs=60)
    for sample in (rng.standard_normal((12000, 8)), rng.uniform(0, 1, (12000, 8))):  # one Gaussian, one flat box
        assert mode_labels(sample).max() == 0
    banana = rng.standard_normal((12000, 8))
    banana[:, 1] = banana[:, 0] ** 2 + 0.1 * banana[:, 1]  # curved but single
    assert mode_labels(banana).max() == 0
