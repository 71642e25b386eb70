"""cubic_stiffening: a k3 z^3 spring beside the joint (a preload-dependent contact, foam compression)."""
from __future__ import annotations

from dataclasses import replace

from ..models import cubic_spring
from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, elements=model.elements + (cubic_spring(v["k3"]),))


def _fingerprint(fp, sigma_db, sigma_f):
    ft = fp.get("f_trend_per_decade") or 0.0
    return abs(ft) > 3 * sigma_f, f"the frequency residual changes by {ft * 100:+.2f}% per decade of level"


def _advice(v):
    return (f"a cubic spring k3 = {v['k3']:.3g} lbf/in^3 acts beside the joint "
            f"({'stiffening' if v['k3'] > 0 else 'softening'} with amplitude): look for a preload-dependent contact "
            "(foam compression, a stop); expect odd harmonics")


def _rescale(sc):
    """+-2.5 K0 / q^2: at the largest amplitude the cubic spring's first harmonic 3/4 k3 q^2 up to about 2 K0
    (the Ministack's own range, +-5e13 lbf/in^3, is this for K0 2e6 lbf/in and q 3e-4 in)."""
    k = 2.5 * sc["K0"] / sc["q"] ** 2
    return {"k3": (-k, k, 0.0)}


EFFECT = Effect(
    "cubic_stiffening", (EffectParam("k3", "lbf/in^3", -5e13, 5e13, False, 0.0, "cubic spring beside the joint"),),
    _apply, _advice, _fingerprint, hidden={"k3": 5e11}, summary="k3 z^3 spring in parallel with the joint",
    rescale=_rescale)
