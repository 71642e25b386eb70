"""The backbone a free decay follows: frequency and damping of the model's first harmonic at each amplitude.

A lightly damped mode ringing down from amplitude q moves, cycle by cycle, as z = q cos(omega t) with q
falling slowly (averaging, the first-harmonic slow flow of `jointcal.models.envelope` without a drive):
the joint DOF's complex dynamic stiffness K(q, omega) = Re K + i Im K (`_envelope_kernel._stiffness`, the
describing functions of the Iwan joint and of every element of `MinistackModel.elements`) balances the
inertia, so

    omega(q)^2 = Re K(q) / m,       zeta(q) = Im K(q, omega(q)) / (2 Re K(q)),

the decay rate over the frequency (dq/dt = -zeta omega q). Re K does not depend on omega; Im K is
omega c (the dashpot c = 2 zeta_v sqrt((k + KT) m)) plus the joint's and elements' hysteresis D / (pi q^2),
plus a quadratic damper's 8 a omega^2 q / (3 pi): quadratic in omega, so one kernel call at omega = 0
gives Im K at every omega (its value, slope C and curvature C1 there).

Closed forms it meets (tests/models/test_free_decay.py): with no element it is `harmonic_balance`
(dashpot convention) to round-off; a cubic spring k3 z^3 beside a linear mode is Duffing's backbone
omega^2 = omega_0^2 + 3/4 k3 q^2 / m; a backbone share s gives (1 - s) of the Iwan joint's damping at the
stiffness (1 - s) K_iwan + s k_b.

What a decay read-out does not see, the backbone leaves out: the sensor's delay (a free decay has no phase
against a drive) and a neighbouring mode (`MinistackModel.neighbour`: the read-out band-passes the mode).
The sensor gain scales the amplitude read: the backbone at q is the model's at q / gain. A flexible
fixture couples a second DOF into the mode: no one-DOF backbone, refused in one sentence.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _envelope_kernel as _k
from .envelope import GAUSS_NODES, GAUSS_WEIGHTS, batch_field, batch_shape, joint_terms
from .structure import MinistackModel

__all__ = ["free_backbone"]


def free_backbone(model: MinistackModel, q_in: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Frequency (Hz) and damping ratio of the model's free decay at amplitudes q.

    Parameters
    ----------
    model : MinistackModel
        Structure, joint and elements; numeric fields may be batched (P, 1) as for `steady_state`.
        No fixture.
    q_in : array_like, shape (N,)
        Amplitudes the sensor reads, in (> 0): the mode's displacement at the response sensor
        (the joint's relative displacement on the Ministack), times the sensor gain.

    Returns
    -------
    f_hz, zeta : ndarray, shape broadcast(parameter shape, (N,))
        Frequency (Hz) and damping ratio (-) of the first harmonic at each amplitude; NaN where
        Re K <= 0 (no oscillation).
    """
    q = np.atleast_1d(np.asarray(q_in, dtype=float))
    if q.ndim != 1 or not np.all(np.isfinite(q) & (q > 0)):
        raise ValueError("free_backbone: q_in must be a 1-D array of positive, finite amplitudes in inches.")
    if model.fixture is not None:
        raise ValueError("free_backbone: a flexible fixture couples the can's DOF into the mode; a free decay has no "
                         "one-DOF backbone then (simulate it with jointcal.models.simulate).")
    shape, out_shape = batch_shape(model, q.shape)
    P, N = shape
    m = batch_field(model.m, shape)[:, None]
    gain = batch_field(model.sensor_gain, shape)[:, None]
    qq = np.ascontiguousarray(np.broadcast_to(q / np.abs(gain), (P, N)))  # the joint's amplitude
    k, c, KT, R, chi, phimax, S, J1, codes, coefs = joint_terms(model, shape)
    out = np.empty((6, P, N))
    _k.stiffness_slopes(qq, np.zeros(N), k, c, KT, R, chi, phimax, S, J1, codes, coefs, GAUSS_NODES, GAUSS_WEIGHTS,
                        out)
    re, im0, C0, C1 = out[0], out[1], out[4], out[5]
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.sqrt(np.where(re > 0, re, np.nan) / m)
        im = im0 + C0 * w + 0.5 * C1 * w**2  # Im K at omega: its value, slope and curvature at omega = 0
        zeta = im / (2.0 * re)
    return (w / (2 * np.pi)).reshape(out_shape), zeta.reshape(out_shape)
