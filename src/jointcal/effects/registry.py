"""The registry of effects: register, look up by name, apply (alone or joined)."""
from __future__ import annotations

from collections.abc import Mapping

from ..models import MinistackModel
from .effect import Effect

__all__ = ["EFFECTS", "JOIN", "register", "library", "effects_of", "apply_effect"]

EFFECTS: dict[str, Effect] = {}
JOIN = "+"  # effects present together: "fixture_flexibility+quadratic_damping"


def register(effect: Effect) -> Effect:
    """Add an effect to the registry (synth, the envelope model, the time simulation and the
    discrepancy workflow then all know it); its parameter names must be new."""
    if JOIN in effect.name or effect.name in ("none", "baseline", "unexplained"):
        raise ValueError(f"effect name {effect.name!r} is reserved or holds {JOIN!r}; choose another.")
    taken = {p.name: e.name for e in EFFECTS.values() if e.name != effect.name for p in e.params}
    clash = [p.name for p in effect.params if p.name in taken]
    if clash:
        raise ValueError(f"effect {effect.name!r}: parameter name(s) {clash} already belong to "
                         f"{sorted({taken[c] for c in clash})}; effects joined by {JOIN!r} need distinct names.")
    EFFECTS[effect.name] = effect
    return effect


def library(kind: str | None = None) -> tuple[str, ...]:
    """The effects the discrepancy workflow tries, in registry order (of one model kind, or of any)."""
    return tuple(n for n, e in EFFECTS.items() if e.library and (kind is None or kind in e.kinds))


def effects_of(name: str) -> tuple[str, ...]:
    """The library effects of a model name: () for 'baseline', one or more joined by `JOIN`."""
    if name == "baseline":
        return ()
    parts = tuple(name.split(JOIN))
    bad = [p for p in parts if p not in EFFECTS]
    if bad or len(set(parts)) != len(parts):
        raise ValueError(f"unknown effect(s) {', '.join(bad) or name!r}; the library has {', '.join(EFFECTS)} "
                         f"(join distinct effects with {JOIN!r}).")
    return parts


def apply_effect(model: MinistackModel, name: str, values: Mapping[str, float], row: Mapping) -> MinistackModel:
    """The model with effect(s) `name` at `values` for the run of manifest `row` ('baseline': unchanged).

    Joined effects ("a+b") are applied in turn; each reads its own parameters from `values`
    (parameter names are distinct across the registry)."""
    for e in effects_of(name):
        model = EFFECTS[e].apply(model, values, row)
    return model
