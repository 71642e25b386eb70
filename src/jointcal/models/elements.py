"""Nonlinear elements in parallel with the joint: the element table the kernels read.

An effect that adds a force on the joint DOF (z the joint's relative displacement, in)
adds an `Element` to `MinistackModel.elements`. The kernels (time integrator and
envelope model) see all of them as one table: integer codes and a coefficient array,
so a new kind of element costs a code here, one inline function in each kernel
(`_integrator._element`, `_envelope_kernel._element`) and no change of signature.

==================  ====  =========================  ====================  =====================
element             code  force                      a                     b
==================  ====  =========================  ====================  =====================
cubic spring        1     a z^3                      lbf/in^3              (unused)
contact spring      2     a max(z - b, 0)            lbf/in (>= 0)         gap, in (>= 0)
quadratic damper    3     a z'|z'|                   lbf s^2/in^2          (unused)
backbone share      4     -a (F_iwan - F_b(z))       share s, [0, 1)       (unused)
==================  ====  =========================  ====================  =====================

The table is sorted by code: the kernels evaluate the velocity-dependent elements last
(their force enters the acceleration their tangent needs). The contact spring has no
first-harmonic model (a mean offset, even harmonics): only the time simulation takes it.
The backbone share (a non-Masing joint: `jointcal.synth.non_masing`, the effect
`jointcal.effects.elastic_softening`) makes the exact Iwan joint's force
(1 - s) F_iwan(history) + s F_b(z), F_b its virgin backbone: the same backbone, (1 - s) of
the dissipation. The envelope kernel's describing function is (1 - s) K_iwan(q) + s k_b(q),
k_b the backbone's first-harmonic stiffness (`_envelope_kernel._backbone_first_harmonic`).
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Element", "CUBIC_SPRING", "CONTACT_SPRING", "QUADRATIC_DAMPER", "BACKBONE_SHARE", "FIRST_HARMONIC",
           "cubic_spring", "contact_spring", "quadratic_damper", "backbone_share", "element_table"]

CUBIC_SPRING = 1
CONTACT_SPRING = 2
QUADRATIC_DAMPER = 3
BACKBONE_SHARE = 4
NAMES = {CUBIC_SPRING: "cubic spring", CONTACT_SPRING: "contact spring", QUADRATIC_DAMPER: "quadratic damper",
         BACKBONE_SHARE: "backbone share"}
FIRST_HARMONIC = frozenset({CUBIC_SPRING, QUADRATIC_DAMPER, BACKBONE_SHARE})  # the envelope kernel has their describing functions


@dataclass(frozen=True)
class Element:
    """One element of the table: its code and coefficients a, b (units in the module table).

    a and b may be arrays of shape (P, 1) (a batch of parameter sets, as every model field).
    """

    code: int
    a: float | NDArray = 0.0
    b: float | NDArray = 0.0

    def __post_init__(self) -> None:
        if self.code not in NAMES:
            raise ValueError(f"element code {self.code!r} is not one of {sorted(NAMES)} ({', '.join(NAMES.values())}).")
        if not (np.all(np.isfinite(self.a)) and np.all(np.isfinite(self.b))):
            raise ValueError(f"{NAMES[self.code]}: coefficients must be finite, got a={self.a!r}, b={self.b!r}.")
        if self.code == BACKBONE_SHARE and not np.all((np.asarray(self.a) >= 0) & (np.asarray(self.a) < 1)):
            raise ValueError(f"backbone share: s must lie in [0, 1) (the share of the joint's force made elastic), "
                             f"got {self.a!r}.")
        if self.code == CONTACT_SPRING and not np.all((np.asarray(self.a) >= 0) & (np.asarray(self.b) >= 0)):
            raise ValueError("contact spring: stiffness and gap must be >= 0 (a contact that pushes back once the "
                             f"gap closes), got {self.a!r} and {self.b!r}.")


def cubic_spring(k3: ArrayLike) -> Element:
    """k3 z^3 beside the joint, k3 in lbf/in^3."""
    return Element(CUBIC_SPRING, k3)


def contact_spring(k: ArrayLike, gap_in: ArrayLike = 0.0) -> Element:
    """k max(z - gap, 0): a stop the slug meets beyond a gap (k lbf/in, gap in)."""
    return Element(CONTACT_SPRING, k, gap_in)


def quadratic_damper(c2: ArrayLike) -> Element:
    """c2 z'|z'| beside the joint, c2 in lbf s^2/in^2."""
    return Element(QUADRATIC_DAMPER, c2)


def backbone_share(s: ArrayLike) -> Element:
    """(1 - s) F_iwan(history) + s F_b(z) in place of the joint's force: s of it elastic along its backbone."""
    return Element(BACKBONE_SHARE, s)


def element_table(elements: Sequence[Element], batch: Callable[[ArrayLike], NDArray] | None = None
                  ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The kernels' table: codes (n,) sorted, and coefficients (n, 2), or (P, n, 2) with `batch`.

    batch : maps a coefficient (scalar or batched model field) to its values over the P
    parameter sets, shape (P,) (`envelope.batch_field`); None takes scalars.
    """
    order = sorted(range(len(elements)), key=lambda i: elements[i].code)
    codes = np.array([elements[i].code for i in order], dtype=np.int64)
    if batch is None:
        coefs = np.array([[float(elements[i].a), float(elements[i].b)] for i in order], dtype=float).reshape(-1, 2)
        return codes, coefs
    P = batch(0.0).shape[0]
    coefs = np.zeros((P, len(order), 2))
    for j, i in enumerate(order):
        coefs[:, j, 0] = batch(elements[i].a)
        coefs[:, j, 1] = batch(elements[i].b)
    return codes, coefs
