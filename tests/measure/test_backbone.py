"""Equal-amplitude line pairs of an FRF peak (jointcal.measure.backbone): a linear
mode's pole at every level, and a bent voltage-driven peak read at its amplitude."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.models import G, MinistackModel

F0, ZETA = 100.0, 0.015  # Hz, damping ratio of the linear test structure


def test_pair_backbone_of_a_linear_frf_is_its_pole():
    """Equal-amplitude pairs of A e^{i theta} / (W^2 - w^2 + 2 i zeta W w): every level gives the pole,
    whatever the (unknown) phase of the modal constant and with a residual term beside it."""
    from jointcal.measure.backbone import backbone_at_peak, pair_backbone

    f = np.linspace(80.0, 120.0, 8001)
    w, W = 2 * np.pi * f, 2 * np.pi * F0
    X = 3.0 * np.exp(-1.0j) / (W**2 - w**2 + 2j * ZETA * W * w)
    bb = pair_backbone(f, X)
    assert len(bb) == 17
    assert np.abs(bb["f_hz"] / F0 - 1).max() < 1e-6 and np.abs(bb["zeta"] / ZETA - 1).max() < 1e-4
    f_p, z_p, spread = backbone_at_peak(bb)
    assert f_p == pytest.approx(F0, rel=1e-6) and z_p == pytest.approx(ZETA, rel=1e-4) and spread < 1e-6
    # a far mode's residual (1% of the peak) moves the read-out by far less than the 0.2% / 5% asked
    bb_r = pair_backbone(f, X + 0.01 * np.abs(X).max())
    f_r, z_r, _ = backbone_at_peak(bb_r)
    assert f_r == pytest.approx(F0, rel=2e-4) and z_r == pytest.approx(ZETA, rel=0.02)


def test_pair_backbone_reads_a_bent_voltage_peak_at_its_amplitude():
    """The steady-state FRF of the Table 3.2 joint on an open-loop shaker (voltage reference), each line
    at its own amplitude (first-harmonic balance of the joint, solved line by line): the pairs give the
    rig's equivalent-linear pole at each level's amplitude, and at the peak the pole at the peak's
    amplitude (the truth `rig_pole`, an independent root of the coupled rig's polynomial). The single-mode
    rational fit of the same bent peak is off by more than the 0.2% a read-out must hold."""
    from jointcal.measure.backbone import backbone_at_peak, pair_backbone
    from jointcal.measure.frf import fit_mode
    from jointcal.models import IwanParams
    from jointcal.synth.rig_truth import _x_over_v, rig_pole
    from jointcal.synth.shaker import Shaker

    model = MinistackModel(m=2.65 / G, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(313.0, 1.02e6, -0.65, 0.004))
    sh, volts = Shaker(), 3.359
    f = np.arange(1900.0, 2500.0, 2.0)
    q = np.empty_like(f)
    for n, fi in enumerate(f):  # q = V |x/V(w; q)|: one root per line at this level (no fold)
        lo, hi = np.log(1e-9), np.log(1e-3)
        for _ in range(50):
            mid = 0.5 * (lo + hi)
            big = volts * abs(_x_over_v(model, sh, np.exp(mid), np.array([2 * np.pi * fi]))[0]) > np.exp(mid)
            lo, hi = (mid, hi) if big else (lo, mid)
        q[n] = np.exp(0.5 * (lo + hi))
    X = np.array([_x_over_v(model, sh, qi, np.array([2 * np.pi * fi]))[0] for qi, fi in zip(q, f)])
    bb = pair_backbone(f, X)
    assert len(bb) >= 15
    q_pk = q.max()
    for r in bb.itertuples():
        f_t, z_t = rig_pole(model, sh, r.level * q_pk)
        assert r.f_hz == pytest.approx(f_t, rel=1e-3) and r.zeta == pytest.approx(z_t, rel=0.05)
    f_t, z_t = rig_pole(model, sh, q_pk)
    f_p, z_p, _ = backbone_at_peak(bb)
    assert f_p == pytest.approx(f_t, rel=1e-3) and z_p == pytest.approx(z_t, rel=0.05)
    fit = fit_mode(f, X, (f[0], f[-1]))
    assert abs(fit.f_n_hz / f_t - 1) > 2e-3  # what the pairs replace
