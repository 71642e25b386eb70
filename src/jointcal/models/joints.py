"""Integration of a linear system with an exact Iwan joint on each of several DOFs.

`jointcal.models.simulate.integrate` holds one joint; two jointed modes coupled through a
shaker's coil and armature (`jointcal.synth.shaker`) cannot be integrated apart, so
`integrate_joints` runs the same kernel (`jointcal.models._integrator.run`: exact propagation
of the stuck-joint system, cubic Hermite input and remainders, predict-evaluate-correct,
reversals located inside the step) with one remainder and one turning-point state per joint.
Kept out of `simulate` (and of the package's namespace) so the workflow's stages, which import
`jointcal.models`, do not depend on it.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .iwan import IwanParams
from .simulate import _joint, _run_kernel

__all__ = ["integrate_joints"]


def integrate_joints(A: NDArray, bu: NDArray, BF: NDArray, LZ: NDArray, LV: NDArray, u: NDArray, fs: float,
                     n_sub: int, joints: Sequence[IwanParams | None],
                     outputs: Sequence[tuple[NDArray, float, NDArray]]) -> tuple[NDArray, NDArray]:
    """Integrate x' = A x + bu u + BF r from rest, r_j the remainder of an exact Iwan joint on z_j = LZ[j].x.

    The scheme and the kernel of `integrate` (`jointcal.models._integrator.run`), each joint with its own
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
    BF, LZ, LV = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (BF, LZ, LV))
    J = len(joints)
    if BF.shape != (A.shape[0], J) or LZ.shape != (J, A.shape[0]) or LV.shape != LZ.shape:
        raise ValueError(f"integrate_joints: BF {BF.shape}, LZ {LZ.shape}, LV {LV.shape} do not fit "
                         f"{A.shape[0]} states and {J} joints.")
    return _run_kernel(A, bu, BF, LZ, LV, u, fs, n_sub, [_joint(p) for p in joints], outputs)
