"""The backbone a free decay follows (jointcal.models.free_decay) against closed forms: with no element the
harmonic balance of the Iwan mode, a cubic spring beside a linear mode Duffing's backbone, a quadratic damper's
energy-equivalent damping, a backbone share (1 - s) of the Iwan joint's damping."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from jointcal.models import Fixture, IwanParams, MinistackModel, cubic_spring, harmonic_balance, quadratic_damper
from jointcal.models.elements import backbone_share
from jointcal.models.free_decay import free_backbone

JOINT = dict(Fs=4.0, KT=204.0, chi=-0.5, beta=0.1)
K, M, ZV = 818.0, 1.0 / 386.089, 0.008
Q = np.geomspace(1e-5, 3e-2, 40)  # micro- and macroslip (phi_max ~ 0.02 in)
IWAN = MinistackModel(m=M, k=K, zeta_v=ZV, iwan=IwanParams(**JOINT))
LINEAR = MinistackModel(m=M, k=K, zeta_v=0.0)


def test_without_elements_it_is_the_harmonic_balance():
    f, z = free_backbone(IWAN, Q)
    fh, zh = harmonic_balance(Q, *JOINT.values(), K, M, ZV)
    assert np.abs(f / fh - 1).max() < 1e-13 and np.abs(z / zh - 1).max() < 1e-13  # measured 2e-16, 4e-16


def test_a_cubic_spring_gives_duffing_backbone_and_a_quadratic_damper_its_equivalent_damping():
    k3 = 1e6
    f, z = free_backbone(replace(LINEAR, elements=(cubic_spring(k3),)), Q)
    assert np.abs(f / (np.sqrt((K + 0.75 * k3 * Q**2) / M) / (2 * np.pi)) - 1).max() < 1e-13 and not z.any()
    c2 = 0.5
    f, z = free_backbone(replace(LINEAR, elements=(quadratic_damper(c2),)), Q)
    w0 = np.sqrt(K / M)  # zeta = c_eq / (2 m w) with w c_eq = 8 c2 w^2 q / (3 pi)
    assert np.allclose(f, w0 / (2 * np.pi), rtol=1e-14)
    assert np.abs(z / (8 * c2 * w0 * Q / (3 * np.pi) / (2 * M * w0)) - 1).max() < 1e-13


def test_a_backbone_share_keeps_1_minus_s_of_the_joints_damping_and_batches():
    s = 0.7
    f, z = free_backbone(replace(IWAN, zeta_v=0.0, elements=(backbone_share(s),)), Q)
    fh, zh = harmonic_balance(Q, *JOINT.values(), K, M, 0.0)
    d, dh = z * (2 * np.pi * f) ** 2, zh * (2 * np.pi * fh) ** 2  # Im K / 2m: the dissipation, frequency aside
    assert np.abs(d / dh - (1 - s)).max() < 1e-12
    assert np.all(f >= fh * (1 - 1e-12))  # the elastic backbone's secant-like stiffness: no lower
    batch = replace(IWAN, iwan=IwanParams(np.array([[4.0], [6.0]]), 204.0, -0.5, 0.1))
    fb, zb = free_backbone(batch, Q)
    assert fb.shape == (2, Q.size) and np.array_equal(fb[0], free_backbone(IWAN, Q)[0])


def test_what_a_decay_does_not_see_and_a_fixture_refused():
    f, z = free_backbone(IWAN, Q)
    fd, zd = free_backbone(replace(IWAN, sensor_delay_s=1e-3), Q)
    assert np.array_equal(f, fd) and np.array_equal(z, zd)
    fg, _ = free_backbone(replace(IWAN, sensor_gain=2.0), 2 * Q)
    assert np.allclose(fg, f, rtol=1e-14)  # the gain scales the amplitude read
    with pytest.raises(ValueError, match="flexible fixture"):
        free_backbone(replace(IWAN, fixture=Fixture(0.01, 400.0)), Q)
