"""Integration of a linear system with an exact Iwan joint on each of several DOFs.

`jointcal.models.simulate.integrate` holds one joint; two jointed modes coupled through a
shaker's coil and armature (`jointcal.synth.shaker`) cannot be integrated apart, so
`integrate_joints` runs the same scheme (`jointcal.models._joints_kernel`: exact propagation
of the stuck-joint system, cubic Hermite input and remainders, predict-evaluate-correct,
reversals located inside the step) with one remainder and one turning-point state per joint.
Kept out of `simulate` (and of the package's namespace) so the workflow's stages, which import
`jointcal.models`, do not depend on it.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from . import _integrator, _joints_kernel
from .iwan import IwanParams
from .simulate import _joint, _substep_maps, hermite_propagator

__all__ = ["integrate_joints"]


def integrate_joints(A: NDArray, bu: NDArray, BF: NDArray, LZ: NDArray, LV: NDArray, u: NDArray, fs: float,
                     n_sub: int, joints: Sequence[IwanParams | None],
                     outputs: Sequence[tuple[NDArray, float, NDArray]]) -> tuple[NDArray, NDArray]:
    """Integrate x' = A x + bu u + BF r from rest, r_j the remainder of an exact Iwan joint on z_j = LZ[j].x.

    The scheme of `integrate` (`jointcal.models._joints_kernel`), each joint with its own
    turning-point state: r_j = F_iwan,j(z_j) - KT_j z_j, A holding every joint stuck. With one
    joint, or with all joints but one None, the result is `integrate`'s bit for bit.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        The linear system with every joint stuck.
    bu : ndarray, shape (n,)
        Input map (the units of u: V for a drive voltage).
    BF : ndarray, shape (n, J)
        Map of each joint's remainder (lbf).
    LZ, LV : ndarray, shape (J, n)
        Joint displacements z = LZ.x (in) and rates z' = LV.x (in/s).
    u : ndarray, shape (N,)
        Input at the samples.
    fs : float
        Sample rate of u, Hz.
    n_sub : int
        Integration substeps per sample.
    joints : sequence of IwanParams or None, length J
        Joint j's parameters; None: no joint on that DOF (r_j = 0).
    outputs : sequence of (c (n,), du, df (J,))
        Output channels y = c.x + du u + df.r.

    Returns
    -------
    Y : ndarray, shape (n_outputs, N)
        The outputs at the samples.
    Z : ndarray, shape (J, N)
        The joint displacements at the samples, in.
    """
    u = np.ascontiguousarray(u, dtype=float)
    BF, LZ, LV = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (BF, LZ, LV))
    J = len(joints)
    if BF.shape != (A.shape[0], J) or LZ.shape != (J, A.shape[0]) or LV.shape != LZ.shape:
        raise ValueError(f"integrate_joints: BF {BF.shape}, LZ {LZ.shape}, LV {LV.shape} do not fit "
                         f"{A.shape[0]} states and {J} joints.")
    h = 1.0 / fs / n_sub
    Phi, Gu = hermite_propagator(A, bu, h)
    Gf = np.ascontiguousarray(np.stack([hermite_propagator(A, BF[:, j], h)[1] for j in range(J)]))
    Gsub, Wub = _substep_maps(Gu, n_sub)
    maps = (1.0 / fs, Gsub, Wub, np.ascontiguousarray(Phi), Gf, np.ascontiguousarray(LZ), np.ascontiguousarray(LV))
    outs = (np.ascontiguousarray(np.array([np.asarray(c, float) for c, _, _ in outputs])),
            np.array([float(d) for _, d, _ in outputs]),
            np.ascontiguousarray(np.array([np.broadcast_to(np.asarray(d, float), (J,)) for _, _, d in outputs])))
    cols = [_joint(p, None)[0] for p in joints]
    kinds = (np.array([c[0] for c in cols], dtype=np.int64),
             *(np.array([c[i] for c in cols], dtype=float) for i in range(1, 6)))
    Y = np.empty((len(outputs), u.size))
    Z = np.empty((J, u.size))
    _joints_kernel.run_joints(u, _integrator.rate(u, fs), maps, outs, kinds, Y, Z)
    return Y, Z
