"""Several exact Iwan joints in one integration (jointcal.models.joints): the one-joint integrator bit for bit
when only one joint is present, and each of two uncoupled joints as if integrated alone.

(The coupled case, two jointed modes on a shaker, is checked against the joints' closed-form dissipation in
tests/synth/test_shaker.py.)
"""
import numpy as np

from jointcal.models import G, IwanParams, MinistackModel
from jointcal.models.joints import integrate_joints
from jointcal.models.simulate import integrate
from jointcal.models.structure import StateSpace, state_space
from tests._support.lockin import linear_sweep

M = 2.65 / G
TABLE_3_2 = MinistackModel(m=M, k=6.12e5, zeta_v=0.0015, iwan=IwanParams(313, 1.02e6, -0.65, 0.004))


def _two_oscillators(models):
    """Uncoupled oscillators on one force input (lbf): state [z_1, z_1', z_2, z_2', ...], joint j on z_j."""
    n = 2 * len(models)
    A, bu, BF = np.zeros((n, n)), np.zeros(n), np.zeros((n, len(models)))
    for j, md in enumerate(models):
        ks = md.k + md.KT
        A[2 * j, 2 * j + 1] = 1.0
        A[2 * j + 1, 2 * j: 2 * j + 2] = [-ks / md.m, -2 * md.zeta_v * np.sqrt(ks * md.m) / md.m]
        bu[2 * j + 1], BF[2 * j + 1, j] = 1.0 / md.m, -1.0 / md.m
    return A, bu, BF


def test_several_joints_reduce_to_the_one_joint_integrator_bit_for_bit():
    """`integrate_joints` with one joint, or with a second DOF whose joint is absent, is `integrate`
    to the last bit (the same arithmetic in the same order)."""
    fs = 8192.0
    u = linear_sweep(1900.0, 2300.0, 2000.0, fs, 5.0 * G)[3]  # 5 g over the resonance: the joint slips
    ss = state_space(TABLE_3_2)
    Y1, z1 = integrate(ss, u, fs, 2, iwan=TABLE_3_2.iwan)
    Y2, z2 = integrate_joints(ss.A, ss.bu, ss.bf[:, None], ss.lz[None], ss.lv[None], u, fs, 2, [TABLE_3_2.iwan],
                              [(ss.cy, ss.dyu, np.array([ss.dyf]))])
    assert np.array_equal(Y1, Y2) and np.array_equal(z1, z2[0])
    other = MinistackModel(m=M, k=4e6, zeta_v=0.01)
    A, bu, BF = _two_oscillators([TABLE_3_2, other])
    E = np.eye(4)
    Y3, Z3 = integrate_joints(A, bu, BF, E[[0, 2]], E[[1, 3]], u, fs, 2, [TABLE_3_2.iwan, None],
                              [(E[0] + E[2], 0.0, np.zeros(2))])
    Y4, z4 = integrate(StateSpace(A, bu, BF[:, 0], E[0] + E[2], 0.0, 0.0, E[0], E[1]), u, fs, 2,
                       iwan=TABLE_3_2.iwan)
    assert np.array_equal(Y3, Y4) and np.array_equal(Z3[0], z4)


def test_two_uncoupled_joints_are_each_integrated_as_if_alone():
    """Two jointed oscillators on one force, integrated together, against each integrated alone by
    `integrate`: each joint keeps its own turning points (round-off apart)."""
    m = 1.0 / G
    models = [MinistackModel(m=m, k=818.0, zeta_v=0.008, iwan=IwanParams(4.0, 204.0, -0.5, 0.1)),
              MinistackModel(m=m, k=4327.0, zeta_v=0.006, iwan=IwanParams(4.0, 1079.0, -0.5, 0.1))]
    fs = 4096.0
    u = linear_sweep(60.0, 300.0, 30.0, fs, 0.3)[3]  # a 0.3 lbf chirp over both modes
    A, bu, BF = _two_oscillators(models)
    E = np.eye(4)
    Y, Z = integrate_joints(A, bu, BF, E[[0, 2]], E[[1, 3]], u, fs, 2, [md.iwan for md in models],
                            [(E[0] + E[2], 0.0, np.zeros(2))])
    alone = []
    for md in models:
        a, b, bf = _two_oscillators([md])
        alone.append(integrate(StateSpace(a, b, bf[:, 0], np.eye(2)[0], 0.0, 0.0, np.eye(2)[0], np.eye(2)[1]), u,
                               fs, 2, iwan=md.iwan)[1])
    for j, md in enumerate(models):
        q = np.abs(Z[j]).max()
        a, b, bf = _two_oscillators([md])
        linear = integrate(StateSpace(a, b, bf[:, 0], np.eye(2)[0], 0.0, 0.0, np.eye(2)[0], np.eye(2)[1]), u, fs, 2)[1]
        assert np.abs(alone[j] - linear).max() > 0.05 * q  # each joint matters
        assert np.abs(Z[j] - alone[j]).max() < 1e-9 * q
    assert np.abs(Y[0] - alone[0] - alone[1]).max() < 1e-9 * np.abs(Y[0]).max()
