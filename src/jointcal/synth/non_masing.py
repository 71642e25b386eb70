"""A joint that softens more than Masing allows for its damping: the virtual lab's test of the verdict.

An Iwan joint obeys Masing's rules: its hysteresis loop is its backbone scaled by two, so
the backbone that sets how far the frequency falls with amplitude also sets the energy a
cycle dissipates. A real joint need not: part of its softening can be elastic (contact
area that grows and shrinks without slip). The virtual lab builds one by giving a share
s of the joint's force to the nonlinear elastic spring along the same backbone:

    F(t) = (1 - s) F_iwan(z history) + s F_b(z(t)),

F_b the virgin backbone of `jointcal.models.iwan.backbone`. The backbone (a monotonic
loading from rest) is unchanged, so the low-amplitude softening is about the Iwan
joint's, while the dissipation per cycle is (1 - s) D_iwan(q) exactly (the elastic part
returns what it takes). A four-parameter Iwan joint fitted to it must then either soften
as measured with too much damping or damp as measured with too little softening.

The time simulation takes it as the element ``backbone share`` (code 4,
`jointcal.models.elements.backbone_share`); `first_harmonic` gives the truth's
equivalent-linear stiffness and dissipation at an amplitude by integrating the force law
over a cycle, and `equivalent` the structure's frequency and damping from them.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..models import IwanParams, MinistackModel, backbone, force_history
from ..models.elements import BACKBONE_SHARE, backbone_share

__all__ = ["KEY", "with_share", "share_of", "blended_force", "first_harmonic", "equivalent"]

KEY = "backbone_share"  # an assembly's key in a truth spec (0 <= s < 1; 0 or absent: the Iwan joint)


def with_share(model: MinistackModel, s: float) -> MinistackModel:
    """The model with a share ``s`` of its joint's force made elastic along the backbone (s = 0: unchanged)."""
    if not 0.0 <= s < 1.0:
        raise ValueError(f"{KEY} must lie in [0, 1) (the share of the joint's force made elastic), got {s!r}.")
    if s == 0.0:
        return model
    if model.iwan is None:
        raise ValueError(f"{KEY} {s:g} needs a joint: give the assembly Fs, KT, chi and beta.")
    return replace(model, elements=model.elements + (backbone_share(s),))


def share_of(model: MinistackModel) -> float:
    """The model's backbone share s (0 without one)."""
    return float(sum(float(e.a) for e in model.elements if e.code == BACKBONE_SHARE))


def blended_force(z: ArrayLike, p: IwanParams, s: float) -> NDArray[np.float64]:
    """(1 - s) F_iwan(z history) + s F_b(z), lbf, along a displacement history z (in) from the virgin state."""
    z = np.asarray(z, dtype=float)
    return (1.0 - s) * force_history(z, p)[0] + s * backbone(z, p)


def first_harmonic(q: float, p: IwanParams, s: float, *, n: int = 4000) -> tuple[float, float]:
    """In-phase stiffness (lbf/in) and dissipation per cycle (lbf in) of the joint in a steady cycle of amplitude q.

    The history rises from rest to q, then runs one cosine cycle q -> -q -> q, sampled at
    ``n`` points; the stiffness is the cycle's first-harmonic coefficient (1/(pi q)) int F cos
    and the dissipation the loop's area, int F dz (trapezoid).
    """
    th = np.linspace(0.0, 2.0 * np.pi, n + 1)
    cycle = q * np.cos(th)
    z = np.r_[np.linspace(0.0, q, n // 4, endpoint=False), cycle]
    F = blended_force(z, p, s)[n // 4:]
    k1 = float(np.trapezoid(F * np.cos(th), th) / (np.pi * q))
    D = float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(cycle)))  # the loop runs clockwise: positive work
    return k1, D


def equivalent(model: MinistackModel, q: float) -> tuple[float, float]:
    """The structure's equivalent-linear natural frequency (Hz) and damping at amplitude q (in), its joint
    taken with its backbone share: omega^2 = (k + k1(q)) / m, zeta = D(q) / (2 pi (k + k1) q^2) + the
    dashpot's zeta_v omega0 / omega (as `jointcal.models.harmonic_balance`)."""
    k1, D = first_harmonic(q, model.iwan, share_of(model))  # type: ignore[arg-type]
    kdf = model.k + k1
    w, w0 = np.sqrt(kdf / model.m), np.sqrt((model.k + model.iwan.KT) / model.m)  # type: ignore[union-attr]
    return float(w / (2 * np.pi)), float(D / (2 * np.pi * kdf * q**2) + model.zeta_v * w0 / w)
