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


EFFECT = Effect(
    "cubic_stiffening", (EffectParam("k3", "lbf/in^3", -5e13, 5e13, False, 0.0, "cubic spring beside the joint"),),
    _apply, _advice, _fingerprint, hidden={"k3": 5e11}, summary="k3 z^3 spring in parallel with the joint")
