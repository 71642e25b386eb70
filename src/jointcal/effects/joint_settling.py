"""joint_settling: the joint's Fs and KT rise over the test series as it beds in.

X_n = X (1 + drift (1 - exp(-(n - 1) / n_settle))) for the run's place n in the sequence.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..models import IwanParams
from .effect import Effect, EffectParam

__all__ = ["EFFECT", "N_SETTLE"]

N_SETTLE = 3.0  # start value of the settling time, runs


def _apply(model, v, row):
    s = 1.0 - np.exp(-(float(row.get("sequence", 1)) - 1.0) / v["n_settle"])
    iw = model.iwan
    return replace(model, iwan=IwanParams(iw.Fs * (1 + v["Fs_drift"] * s), iw.KT * (1 + v["KT_drift"] * s),
                                          iw.chi, iw.beta))


def _fingerprint(fp, sigma_db, sigma_f):
    dr = fp.get("drift_sigma") or 0.0
    return abs(dr) > 3.0, f"the repeated runs drift by {dr:+.1f} scatter units over the sequence"


def _advice(v):
    return (f"the joint settled during the test (Fs {v['Fs_drift'] * 100:+.0f}%, KT {v['KT_drift'] * 100:+.0f}% over "
            f"about {v['n_settle']:.1f} runs): run low-level sweeps until they repeat before the test series, or "
            "calibrate on the settled runs only")


EFFECT = Effect(
    "joint_settling",
    (EffectParam("Fs_drift", "-", -0.5, 1.0, False, 0.05, "relative rise of Fs over the run sequence"),
     EffectParam("KT_drift", "-", -0.5, 1.0, False, 0.05, "relative rise of KT over the run sequence"),
     EffectParam("n_settle", "runs", 0.5, 20.0, True, N_SETTLE, "runs over which the joint settles (1/e)")),
    _apply, _advice, _fingerprint, hidden={"Fs_drift": 0.10, "KT_drift": 0.05, "n_settle": 3.0},
    sequence_dependent=True,
    summary="Fs, KT rise with the run's sequence n: X (1 + drift (1 - exp(-(n - 1) / n_settle)))")
