"""elastic_softening: part of the joint's softening is elastic, so it dissipates less than Masing's rules allow.

An Iwan joint obeys Masing's rules: its hysteresis loop is its virgin backbone F_b scaled by
two, so the backbone that sets how far the frequency falls with amplitude also sets the
energy a cycle dissipates. A real joint need not: contact area that grows and shrinks
without slip softens it elastically. The model keeps the backbone and scales the loss:

    F = r F_iwan(z history) + (1 - r) F_b(z),

the joint's force a share r of the Iwan joint's (with its Masing loops) and 1 - r of an
elastic spring along the same backbone (`jointcal.models.elements.backbone_share`, s = 1 - r).
The monotonic loading curve is unchanged; the dissipation per cycle is exactly r D_iwan(q);
the first-harmonic stiffness is r k_iwan(q) + (1 - r) k_b(q). One parameter, the loss ratio r:
the dissipation per cycle over a Masing joint's of the same backbone (r = 1: the Iwan joint).
"""
from __future__ import annotations

from dataclasses import replace

from ..models.elements import backbone_share
from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, elements=model.elements + (backbone_share(1.0 - v["loss_ratio"]),))


def _fingerprint(fp, sigma_db, sigma_f):
    r = fp.get("masing_ratio")
    seen = r is not None and r < 0.7
    return seen, (f"at the lowest level the measured damping per unit softening is {r:.2f} of the Masing joint's limit"
                  if r is not None else "no level to compare the damping per unit softening with Masing's limit")


def _advice(v):
    r = v["loss_ratio"]
    return (f"this joint dissipates {r:.2f} of what a Masing joint of the same backbone would (its softening is "
            f"{(1 - r) * 100:.0f}% elastic): the Iwan parameters describe its stiffness, not its damping. Predict "
            "its damping with the loss ratio, and check it with a ring-down or a force-displacement loop at the top "
            "level; a contact whose area changes without slip (preload, surface waviness) does this")


EFFECT = Effect(
    "elastic_softening",
    (EffectParam("loss_ratio", "-", 0.05, 1.0, False, 0.6,
                 "dissipation per cycle over a Masing joint's with the same backbone"),),
    _apply, _advice, _fingerprint, hidden={"loss_ratio": 0.3}, kinds=("modal",),
    summary="joint force r F_iwan + (1 - r) F_b: the same backbone, r of the Masing dissipation")
