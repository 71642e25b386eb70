"""quadratic_damping: a c2 z'|z'| damper beside the joint (air pumping through vents, foam cells)."""
from __future__ import annotations

from dataclasses import replace

from ..models import quadratic_damper
from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, elements=model.elements + (quadratic_damper(v["c2"]),))


def _fingerprint(fp, sigma_db, sigma_f):
    zt = fp.get("zeta_trend_per_decade") or 0.0
    ms = fp.get("masing_ratio") or 1.0
    return (zt > 0.05 or ms > 1.3,
            f"the damping residual changes by {zt * 100:+.1f}% per decade of level; Masing ratio {ms:.2f}")


def _advice(v):
    return (f"damping grows with velocity as c2 z'|z'| (c2 = {v['c2']:.3g} lbf s^2/in^2), which no Iwan (Masing) "
            "joint gives: look for air pumping through vents or foam cells; add the damper")


EFFECT = Effect(
    "quadratic_damping",
    (EffectParam("c2", "lbf s^2/in^2", 0.0, 200.0, False, 0.5, "quadratic (velocity-squared) damper"),),
    _apply, _advice, _fingerprint, hidden={"c2": 1.2}, summary="c2 z'|z'| damper beside the joint (air, foam)",
    kinds=("ministack",))
