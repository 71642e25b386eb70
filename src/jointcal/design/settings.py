"""The ``design:`` config section as a frozen settings object, with its defaults.

The defaults equal ``workflow/config/config.yaml``. What counts as identified (the spread
ratio) comes from ``posterior.constrained_ratio``, and the largest sweep-rate parameter a
read-out stays quasi-steady at from ``modal.eta_max``, so the design judges a test as the
posterior and the modal stage would.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

from .._config import config_section

__all__ = ["DesignSettings"]


@dataclass(frozen=True)
class DesignSettings:
    """Settings of the design stage.

    max_level_g : the shaker's (or the fixture's) largest base level, g: no candidate goes
    above it; levels : candidate base levels (g), or empty for the series 1, 1.5, 2, 3, 5, 7
    x 10^n from the campaign's lowest level up to max_level_g; rate_factors : candidate
    sweep rates as multiples of the campaign's rate; directions : candidate sweep
    directions; draws : posterior draws taken, one at a time, as the truth a test would
    meet (the prediction averages over them); confidence : share of those draws for which
    the test must identify Fs and the KT/k split to count as identifying them; frequencies :
    points of the steady-state sweep over the campaign's band; seed : picks the draws.
    """

    max_level_g: float = 100.0
    levels: Sequence[float] = ()
    rate_factors: Sequence[float] = (0.5, 1.0, 2.0, 4.0)
    directions: Sequence[str] = ("up", "down")
    draws: int = 200
    confidence: float = 0.9
    frequencies: int = 400
    seed: int = 2020

    def __post_init__(self) -> None:
        if not self.max_level_g > 0:
            raise ValueError(f"design.max_level_g must be > 0 g, got {self.max_level_g!r}")
        if any(not 0 < v <= self.max_level_g for v in self.levels):
            raise ValueError(f"design.levels must lie in (0, max_level_g = {self.max_level_g:g}] g, got "
                             f"{list(self.levels)!r}")
        if not self.rate_factors or any(not v > 0 for v in self.rate_factors):
            raise ValueError(f"design.rate_factors must be positive multiples of the campaign's rate, got "
                             f"{list(self.rate_factors)!r}")
        if not self.directions or any(d not in ("up", "down") for d in self.directions):
            raise ValueError(f"design.directions must be among up, down, got {list(self.directions)!r}")
        if self.draws < 20:
            raise ValueError(f"design.draws must be >= 20, got {self.draws!r}")
        if not 0 < self.confidence <= 1:
            raise ValueError(f"design.confidence must lie in (0, 1], got {self.confidence!r}")
        if self.frequencies < 50:
            raise ValueError(f"design.frequencies must be >= 50, got {self.frequencies!r}")

    @classmethod
    def from_config(cls, section: Mapping[str, Any] | None) -> DesignSettings:
        """Build from the config's ``design:`` mapping (missing keys take the defaults)."""
        section = config_section(section, (f.name for f in fields(cls)), "design")
        for key in ("levels", "rate_factors", "directions"):
            if key in section:
                section[key] = tuple(section[key])
        return cls(**section)
