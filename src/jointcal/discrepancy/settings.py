"""The ``discrepancy:`` config section."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields

from ..effects import library
from .._config import config_section

__all__ = ["DiscrepancySettings"]


@dataclass(frozen=True)
class DiscrepancySettings:
    """The ``discrepancy:`` config section: candidates (library names), band (fractions of f_res),
    max_frames per run, max_nfev of each least-squares fit, the recalibration's GA generations and
    posterior steps, and its seed."""

    candidates: tuple[str, ...] = field(default_factory=library)
    band: tuple[float, float] = (0.6, 1.4)
    max_frames: int = 80
    max_nfev: int = 25
    ga_generations: int = 30
    posterior_steps: int = 800
    seed: int = 2017

    def __post_init__(self) -> None:
        bad = [c for c in self.candidates if c not in library()]
        if bad:
            raise ValueError(f"discrepancy.candidates: unknown effect(s) {', '.join(bad)}; the library has "
                             f"{', '.join(library())}.")
        if not (0 < self.band[0] < 1 < self.band[1]):
            raise ValueError(f"discrepancy.band must be [lo, hi] with 0 < lo < 1 < hi, got {list(self.band)!r}.")
        if self.ga_generations < 1 or self.posterior_steps < 100:
            raise ValueError("discrepancy.ga_generations must be >= 1 and posterior_steps >= 100, got "
                             f"{self.ga_generations!r} and {self.posterior_steps!r}.")
        if self.max_frames < 16 or self.max_nfev < 5:
            raise ValueError("discrepancy.max_frames must be >= 16 and max_nfev >= 5, got "
                             f"{self.max_frames!r} and {self.max_nfev!r}.")

    @classmethod
    def from_config(cls, section: Mapping | None) -> DiscrepancySettings:
        section = config_section(section, (f.name for f in fields(cls)), "discrepancy")
        for key in ("candidates", "band"):
            if key in section:
                section[key] = tuple(section[key])
        return cls(**section)
