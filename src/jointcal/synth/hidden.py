"""The hidden effect of a virtual campaign: physics the calibrated model does not have.

The effects are those of the registry (`jointcal.effects`, one module each, including
``contact_spring``, which the discrepancy library lacks on purpose); 'none' hides nothing.
A spec names one (and optionally a second, ``also``) with parameter values; those it leaves
out take the effect's hidden strength (``Effect.defaults``: each effect matters at a
realistic strength), e.g. fixture_flexibility's can at 5500 Hz with 4x the slug's mass
(zeta_can is fixed at 1% by the effect), a 40 us channel delay, a 1.25 sensor gain.
"""
from __future__ import annotations

import numpy as np

from ..effects import EFFECTS
from ..models import IwanParams, MinistackModel

__all__ = ["effect_defaults", "run_model"]

NONE = "none"


def effect_defaults(name: str, given: dict | None = None) -> dict[str, float]:
    """Complete an effect's parameters with its hidden defaults; one clear error for unknowns."""
    if name != NONE and name not in EFFECTS:
        raise ValueError(f"unknown hidden effect {name!r}; choose one of {', '.join([NONE, *EFFECTS])}.")
    defaults = {} if name == NONE else EFFECTS[name].defaults
    given = dict(given or {})
    unknown = set(given) - set(defaults)
    if unknown:
        raise ValueError(f"effect {name!r} has no parameter(s) {sorted(unknown)}; "
                         f"its parameters are {sorted(defaults)}.")
    out = {**defaults, **{k: float(v) for k, v in given.items()}}
    if any(not np.isfinite(v) for v in out.values()):
        raise ValueError(f"effect {name!r}: parameters must be finite numbers, got {out}.")
    return out


def run_model(truth: dict, sequence: int, effect: str = NONE, params: dict | None = None) -> MinistackModel:
    """The model that generates one run of an assembly.

    Parameters
    ----------
    truth : dict
        Keys Fs (lbf), KT (lbf/in), chi, beta, k (lbf/in), zeta_v, m (lbf s^2/in).
    sequence : int
        Order of the run within its assembly, from 1 (an effect that changes over the
        test series, e.g. joint_settling, reads it).
    effect, params : str, dict
        The hidden effect and its parameters (completed by `effect_defaults`).
    """
    p = effect_defaults(effect, params)
    iwan = IwanParams(truth["Fs"], truth["KT"], truth["chi"], truth["beta"])
    model = MinistackModel(m=truth["m"], k=truth["k"], zeta_v=truth["zeta_v"], iwan=iwan)
    if effect == NONE:
        return model
    return EFFECTS[effect].apply(model, p, {"sequence": sequence})
