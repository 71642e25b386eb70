"""The ring-down read-out factor: what the estimator reads of a model's simulated decay, over its backbone.

The decay path predicts each measured ring-down point by the model's first-harmonic backbone
(`jointcal.models.free_decay.free_backbone`), while the validation reads the model's time simulation by the
measurement's estimator (`jointcal.validate.decay`: the decay from the record's state at the cut-off, read by
`jointcal.measure.ringdown.ringdown_at` at the measured windows). The two differ where f and zeta change within a
window (near the joint's macroslip knee, in the first windows after the cut) and by the hysteretic joint's memory in a
fast transient (Masing loops under a falling amplitude): a first-order bias against the backbone. As the sweeps'
transient factor does for an envelope (`jointcal.discrepancy.fit.transient_factor`), each point takes

    k_f(q) = f_read(q; theta_ref) / f_bb(q; theta_ref),    k_zeta(q) = zeta_read(q; theta_ref) / zeta_bb(q; theta_ref)
                                                                                        (the read-out factor, R1)

    f_model(q; theta) = f_bb(q; theta) k_f(q),             zeta_model(q; theta) = zeta_bb(q; theta) k_zeta(q)   (R2)

with f_read, zeta_read the estimator's read-out of the candidate's simulated decay at the measured amplitude q
(interpolated in log q along the simulated decay, as the validation compares them) and f_bb, zeta_bb its backbone.
theta_ref is where the factor was taken: held during a least-squares fit, retaken at each optimum
(`decays.DecayObjective.at`), so at convergence the fitted points are the time simulation's read-out, the
validation's like for like. A point the simulation does not reach (outside its decay's amplitudes, up to the
validation's `BEYOND`), a dwell's phase resonance, or a run the simulation refuses keeps the factor 1: the backbone.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..models.free_decay import free_backbone
from ..validate.decay import PART as DECAY
from ..validate.testkinds import validate_test_run
from .fit import Candidate, model_at

__all__ = ["Factor", "simulated_readout", "factor_at", "readout_factor"]

Factor = tuple[NDArray[np.float64], NDArray[np.float64]] | None  # (k_f, k_zeta) at a piece's points, None: 1


def simulated_readout(c: Candidate, theta: NDArray, record: pd.DataFrame | None, row: Mapping,
                      read: Mapping | None = None) -> pd.DataFrame | None:
    """The candidate's simulated ring-down of a run at theta (n,), read as the validation reads it.

    record, row : the run's measured record and its row; read : the record's `measured_read` (read here when None).
    Returns the validation's compared windows (`jointcal.validate.validate_test_run`, ``part`` 'ringdown',
    in range and finite: q_meas_in (in), f_sim_hz (Hz), zeta_sim (-)), None when the run has no record or the
    simulation could not be compared.
    """
    if record is None:
        return None
    frames, _ = validate_test_run(model_at(c, np.asarray(theta, dtype=float), row), record, row, read=read)
    if frames.empty or "part" not in frames:
        return None
    fr = frames[(frames["part"] == DECAY) & frames["in_range"].astype(bool)]
    q, f, z = (fr[k].to_numpy(float) for k in ("q_meas_in", "f_sim_hz", "zeta_sim"))
    ok = np.isfinite(q) & np.isfinite(f) & np.isfinite(z) & (q > 0) & (f > 0) & (z > 0)
    return fr[ok] if ok.any() else None


def factor_at(c: Candidate, theta: NDArray, row: Mapping, q_in: NDArray, read: pd.DataFrame | None) -> Factor:
    """The read-out factor (R1) at amplitudes q_in (in, (n,)) of the run `row` from its simulated read-out `read`
    (`simulated_readout` at the same theta): k_f, k_zeta, shape (n,); 1 outside the read windows' amplitudes,
    None without a read-out."""
    if read is None:
        return None
    q = read["q_meas_in"].to_numpy(float)
    f_bb, z_bb = free_backbone(model_at(c, np.asarray(theta, dtype=float), row), q)
    with np.errstate(all="ignore"):
        kf, kz = read["f_sim_hz"].to_numpy(float) / f_bb, read["zeta_sim"].to_numpy(float) / z_bb
    ok = np.isfinite(kf) & np.isfinite(kz) & (kf > 0) & (kz > 0)
    if not ok.any():
        return None
    o = np.argsort(np.log(q[ok]))
    lq = np.log(q[ok])[o]
    x = np.log(np.asarray(q_in, dtype=float))
    inside = (x >= lq[0] - 1e-9) & (x <= lq[-1] + 1e-9)
    at = lambda k: np.where(inside, np.interp(x, lq, k[ok][o]), 1.0)  # noqa: E731
    return at(kf), at(kz)


def readout_factor(c: Candidate, theta: NDArray, runs: Sequence) -> tuple[Factor, ...]:
    """Every run piece's read-out factor (R1) at theta (n,): each run simulated and read once (its pieces share it).
    runs : the pieces (`decays.DecayRun`: run_id, row, q_in, record, read)."""
    reads: dict[str, pd.DataFrame | None] = {}
    for r in runs:
        if r.run_id not in reads:
            reads[r.run_id] = simulated_readout(c, theta, r.record, r.row, r.read)
    return tuple(factor_at(c, theta, r.row, r.q_in, reads[r.run_id]) for r in runs)
