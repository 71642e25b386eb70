"""Hidden effects: physics the calibrated model does not have, at most one per campaign.

Each effect maps a truth (joint + linear parameters) and a run to the model that
generates that run's data. Defaults make each effect matter at a realistic strength.

=====================  ==========================================================
fixture_flexibility     can of mass m_can_ratio * m on a spring of own frequency
                        f_can_hz (ratio zeta_can) between the control accelerometer
                        and the joint: an extra DOF driven by the base, loaded by the
                        slug (slug mode ~2-3% lower, response ~+20% near 2.2 kHz).
channel_delay           response channel delayed by tau_s (exact fractional delay).
cubic_stiffening        k3 z^3 spring in parallel with the joint (lbf/in^3).
joint_settling          Fs and KT rise with the run's sequence number n:
                        X_n = X (1 + drift (1 - exp(-(n - 1) / n_settle))).
quadratic_damping       c2 z'|z'| damper (lbf s^2/in^2): air pumping, foam.
sensor_gain             response sensitivity off by `gain`, not in the metadata.
contact_spring          unilateral spring contact_k max(z - gap_in, 0) (lbf/in, in):
                        the slug meets a stop (a bottomed foam cup) beyond a gap;
                        asymmetric, so even harmonics and a mean offset. Outside the
                        discrepancy library on purpose (the workflow must not give it
                        a wrong library name with high confidence).
=====================  ==========================================================
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..models import Fixture, IwanParams, MinistackModel

__all__ = ["EFFECTS", "effect_defaults", "run_model"]

EFFECTS: dict[str, dict[str, float]] = {
    "none": {},
    "fixture_flexibility": {"m_can_ratio": 4.0, "f_can_hz": 5500.0, "zeta_can": 0.01},
    "channel_delay": {"tau_s": 40e-6},
    "cubic_stiffening": {"k3": 5e11},
    "joint_settling": {"Fs_drift": 0.10, "KT_drift": 0.05, "n_settle": 3.0},
    "quadratic_damping": {"c2": 1.2},
    "sensor_gain": {"gain": 1.25},
    "contact_spring": {"contact_k": 4e5, "gap_in": 8e-5},
}


def effect_defaults(name: str, given: dict | None = None) -> dict[str, float]:
    """Complete an effect's parameters with its defaults; one clear error for unknowns."""
    if name not in EFFECTS:
        raise ValueError(f"unknown hidden effect {name!r}; choose one of {', '.join(EFFECTS)}.")
    given = dict(given or {})
    unknown = set(given) - set(EFFECTS[name])
    if unknown:
        raise ValueError(f"effect {name!r} has no parameter(s) {sorted(unknown)}; "
                         f"its parameters are {sorted(EFFECTS[name])}.")
    out = {**EFFECTS[name], **{k: float(v) for k, v in given.items()}}
    if any(not np.isfinite(v) for v in out.values()):
        raise ValueError(f"effect {name!r}: parameters must be finite numbers, got {out}.")
    return out


def run_model(truth: dict, sequence: int, effect: str = "none", params: dict | None = None) -> MinistackModel:
    """The model that generates one run of an assembly.

    Parameters
    ----------
    truth : dict
        Keys Fs (lbf), KT (lbf/in), chi, beta, k (lbf/in), zeta_v, m (lbf s^2/in).
    sequence : int
        Order of the run within its assembly, from 1 (used by joint_settling).
    effect, params : str, dict
        The hidden effect and its (completed) parameters.
    """
    p = effect_defaults(effect, params)
    iwan = IwanParams(truth["Fs"], truth["KT"], truth["chi"], truth["beta"])
    model = MinistackModel(m=truth["m"], k=truth["k"], zeta_v=truth["zeta_v"], iwan=iwan)
    if effect == "fixture_flexibility":
        fx = Fixture(m_can=p["m_can_ratio"] * truth["m"], f_can=p["f_can_hz"], zeta_can=p["zeta_can"])
        return replace(model, fixture=fx)
    if effect == "channel_delay":
        return replace(model, sensor_delay_s=p["tau_s"])
    if effect == "cubic_stiffening":
        return replace(model, k3=p["k3"])
    if effect == "quadratic_damping":
        return replace(model, c2=p["c2"])
    if effect == "sensor_gain":
        return replace(model, sensor_gain=p["gain"])
    if effect == "contact_spring":
        return replace(model, contact_k=p["contact_k"], contact_gap_in=p["gap_in"])
    if effect == "joint_settling":
        s = 1.0 - np.exp(-(sequence - 1) / p["n_settle"])
        iw = IwanParams(iwan.Fs * (1 + p["Fs_drift"] * s), iwan.KT * (1 + p["KT_drift"] * s), iwan.chi, iwan.beta)
        return replace(model, iwan=iw)
    return model
