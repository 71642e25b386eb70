"""contact_spring: the slug meets a stop beyond a gap (a bottomed foam cup). Outside the discrepancy library.

A unilateral spring contact_k max(z - gap_in, 0): asymmetric, so even harmonics and a mean
offset, which no first-harmonic model has (only the time simulation takes it). It is kept
out of the library on purpose: the virtual lab hides it to check that the workflow does not
give it a wrong library name with high confidence (`discrepancy.fingerprints.outside_library`).
"""
from __future__ import annotations

from dataclasses import replace

from ..models import contact_spring
from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, elements=model.elements + (contact_spring(v["contact_k"], v["gap_in"]),))


def _advice(v):
    return (f"the slug meets a stop {v['gap_in'] * 1e6:.0f} micro-in away (contact stiffness {v['contact_k']:.3g} "
            "lbf/in): look for a bottoming foam cup or a rattle; expect even harmonics")


EFFECT = Effect(
    "contact_spring",
    (EffectParam("contact_k", "lbf/in", 1e3, 1e8, True, 4e5, "stiffness of the stop once the gap closes"),
     EffectParam("gap_in", "in", 0.0, 1e-3, False, 8e-5, "gap the slug closes before the stop engages")),
    _apply, _advice, None, hidden={"contact_k": 4e5, "gap_in": 8e-5}, library=False,
    summary="unilateral spring contact_k max(z - gap_in, 0): even harmonics, a mean offset")
