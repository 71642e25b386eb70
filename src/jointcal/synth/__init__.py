"""Synthetic test campaigns: a virtual shaker lab with hidden effects."""
from .campaign import generate, plan_runs
from .hidden import effect_defaults, run_model
from .spec import DEFAULT_SPEC, load_spec

__all__ = ["generate", "plan_runs", "effect_defaults", "run_model", "DEFAULT_SPEC", "load_spec"]
