"""A decay read through the force that still acts on it (jointcal.measure.forced_decay) against closed forms: a
linear mode on a linear shaker (armature, suspension, coil), whose coupled pole and whose own pole are both exact,
and the exact Iwan beam on its shaker, held against the structure's first-harmonic balance."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.measure.forced_decay import forced_decay_backbone, structure_pole
from jointcal.measure.ringdown import ringdown_backbone
from jointcal.models import MinistackModel
from jointcal.synth.rig_truth import structure_equivalent
from jointcal.synth.shaker import Shaker, StructureMode, rig_matrices, simulate_rig
from jointcal.units import G
from tests._support import rigs

SHAKER = Shaker(**{**Shaker().__dict__, **rigs.SMALL_SHAKER})
LINEAR = MinistackModel(m=1.0 / G, k=1022.0, zeta_v=0.01)  # the beam's stuck stiffness, 100 Hz, 1 lbf
W_N = np.sqrt(LINEAR.k / LINEAR.m)


def _second(with_second: bool) -> StructureMode | None:
    return StructureMode(**rigs.SECOND_MODE) if with_second else None


def _residual(second: StructureMode | None, s: complex) -> complex:
    """The second mode's receptance at s (in/lbf): 1 / (m_2 s^2 + c_2 s + k_2); 0 without one."""
    return 0.0 if second is None else 1.0 / (second.m * s**2 + second.c * s + second.k)


@pytest.mark.parametrize("with_second", [False, True])
def test_the_structures_pole_from_the_rigs_eigenvector_is_exact(with_second):
    # the coupled rig's eigenvalue near the mode and its eigenvector's acceleration and gauge force: the decay as
    # the two channels see it. The rig rings 2.3% below the structure, 1.4x as damped; read through the force the
    # structure's own wn and zeta come back to rounding
    second = _second(with_second)
    A_rig, _, _, outs = rig_matrices(LINEAR, SHAKER, second)
    ev, V = np.linalg.eig(A_rig)
    i = int(np.argmin(np.abs(ev - W_N * (-0.01 + 1j))))
    s, v = ev[i], V[:, i]
    x = (outs["accel"][0] @ v) / s**2  # the driving point's displacement
    P = outs["force"][0] @ v
    assert 0.02 < 1 - abs(s) / W_N < 0.03 and -s.real / abs(s) > 1.4 * 0.01  # the rig's pole is not the structure's
    wn, zeta = structure_pole(s, P / x, 1.0 / LINEAR.m, _residual(second, s))
    assert abs(wn[0] / W_N - 1) < 1e-9 and abs(zeta[0] / 0.01 - 1) < 1e-9
    if with_second:  # without the second mode's flexibility: -0.05% in f, +1% in zeta
        wn0, zeta0 = structure_pole(s, P / x, 1.0 / LINEAR.m)
        assert 3e-4 < 1 - wn0[0] / W_N < 1e-3 and 0.005 < zeta0[0] / 0.01 - 1 < 0.02


def test_without_a_force_it_is_the_free_decays_read_out():
    s = np.array([-3.0 + 600.0j, -1.0 + 100.0j])
    wn, zeta = structure_pole(s, np.zeros(2), 386.0, 4e-4)
    assert np.allclose(wn, np.abs(s), rtol=1e-12) and np.allclose(zeta, -s.real / np.abs(s), rtol=1e-12)
    with pytest.raises(ValueError, match="positive imaginary part"):
        structure_pole(np.array([-3.0 - 600.0j]), np.zeros(1), 386.0)


def _dwell_then_cut(model, second, volts: float, f_hz: float, fs: float = 2048.0, dwell_s: float = 1.5,
                    decay_s: float = 2.5, noise: float = 1e-3, seed: int = 0):
    """A voltage dwell at f_hz cut to zero; the driving point's acceleration (g) and the gauge's force (lbf), each
    with white noise of `noise` times its rms (the virtual lab's 0.1%)."""
    t = np.arange(int((dwell_s + decay_s) * fs)) / fs
    V = volts * np.sin(2 * np.pi * f_hz * t) * (t < dwell_s)
    acc, F, _ = simulate_rig(model, SHAKER, V, fs, second=second)
    rng = np.random.default_rng(seed)
    acc = acc + noise * np.std(acc) * rng.standard_normal(t.size)
    F = F + noise * np.std(F) * rng.standard_normal(t.size)
    return fs, acc, F, int(dwell_s * fs)


@pytest.mark.parametrize("with_second", [False, True])
def test_a_linear_mode_on_its_shaker_reads_its_own_pole_where_its_ring_down_reads_the_rigs(with_second):
    second = _second(with_second)
    fs, acc, F, cut = _dwell_then_cut(LINEAR, second, 1.0, 97.6)
    A_rig, *_ = rig_matrices(LINEAR, SHAKER, second)
    ev = np.linalg.eigvals(A_rig)
    s_rig = ev[int(np.argmin(np.abs(ev - W_N * (-0.01 + 1j))))]
    bb = forced_decay_backbone(acc, F, fs, 97.0, 1.0 / LINEAR.m, residual=_residual(second, s_rig), start=cut)
    assert np.log10(bb["q_in"].max() / bb["q_in"].min()) >= 1.5
    assert np.abs(bb["f_hz"] / (W_N / (2 * np.pi)) - 1).max() < 1e-3  # the lines, the structure's pole
    assert np.abs(bb["zeta"] / 0.01 - 1).max() < 0.03
    assert np.abs(bb["f_rig_hz"] / (abs(s_rig) / (2 * np.pi)) - 1).max() < 3e-4  # the decay is the rig's
    assert bb["flags"].iloc[-1] == "noise_floor"
    # read as a free decay the same record gives the rig's pole, 2.3% below the structure's
    rd = ringdown_backbone(acc, fs, 97.0, start=cut)
    assert (1 - rd["f_hz"] / (W_N / (2 * np.pi)) > 0.02).all()


def test_the_exact_iwan_beam_on_its_shaker_reads_the_structures_harmonic_balance():
    # the jointed beam of tests/_support/rigs.py (exact Iwan, 230 Hz second mode, small shaker) dwelt at the top
    # level's rig resonance, cut off; read with its modal constant 1/m and the second mode's receptance at the
    # decay's frequency (the estimator's own accuracy: where a campaign measures them, tests/synth/test_forced.py)
    model, sh, second = rigs.rig()
    f_rig, _ = rigs.truth_curve("voltage", rigs.Q_TARGETS[2])
    fs, acc, F, cut = _dwell_then_cut(model, second, rigs.levels_V()[2], f_rig)
    s = 2j * np.pi * f_rig
    bb = forced_decay_backbone(acc, F, fs, f_rig, 1.0 / model.m, residual=_residual(second, s), start=cut)
    f_t, z_t = np.array([structure_equivalent(model, q) for q in bb["q_in"]]).T
    assert np.log10(bb["q_in"].max() / bb["q_in"].min()) >= 1.5
    assert np.abs(bb["f_hz"] / f_t - 1).max() < 1e-3 and np.abs(bb["zeta"] / z_t - 1).max() < 0.03
    assert (bb["f_rig_hz"] / f_t - 1 < -0.02).all()  # the decay itself rings at the rig's pole
    assert bb["f_hz"].iloc[-1] / bb["f_hz"].iloc[0] - 1 > 0.01  # the joint stiffens as it decays


def test_bad_input_is_said_in_one_sentence():
    x = np.zeros(4096)
    with pytest.raises(ValueError, match="one record's channels"):
        forced_decay_backbone(x, x[:10], 2048.0, 97.0, 386.0)
    with pytest.raises(ValueError, match="modal constant must be a finite, nonzero"):
        forced_decay_backbone(x, x, 2048.0, 97.0, 0.0)
    with pytest.raises(ValueError, match="Nyquist"):
        forced_decay_backbone(x, x, 2048.0, 900.0, 386.0, start=0)
