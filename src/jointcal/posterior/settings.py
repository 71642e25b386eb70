"""The ``posterior:`` config section as a frozen settings object, with its defaults.

The defaults equal ``workflow/config/config.yaml``. The model, viscous
convention, damping estimator, slug weight and bounds come from the ``calibrate:``
section (`jointcal.calibrate.CalibrateSettings`), so the posterior is that of the
calibrated model.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from .._config import config_section

__all__ = ["PosteriorSettings"]


@dataclass(frozen=True)
class PosteriorSettings:
    """Settings of the posterior stage.

    seed : seeds emcee's RandomState and the initial ball; n_walkers : walkers (>= 2 * 8);
    max_steps : hard cap on the chain length, steps; chunk : steps between convergence
    checks and checkpoints; tau_factor, tau_rtol : stop when the chain is longer than
    tau_factor * max(tau) and tau moved by less than tau_rtol; stop_projected : stop early
    when the chain length tau_factor * tau needs, extrapolated from the running tau, exceeds
    stop_projected * max_steps at two checks in a row (0: never); min_chunks : checks before
    that is considered; burn_tau : burn-in
    discarded, in units of max(tau); ball : standard deviation of the initial ball around
    the GA optimum, as a fraction of each prior width; rel_std_floor : smallest relative
    noise of frequency and damping (used when the pooled scatter is missing, zero or
    smaller); noise_max : upper bounds of the sampled relative noise scales;
    constrained_ratio : posterior/prior 90%-width ratio below which a parameter counts as
    constrained; predictive_draws : posterior draws behind the predictive band.
    """

    seed: int = 2018
    n_walkers: int = 32
    max_steps: int = 40000
    chunk: int = 1000
    tau_factor: float = 50.0
    tau_rtol: float = 0.05
    stop_projected: float = 1.5
    min_chunks: int = 5
    burn_tau: float = 5.0
    ball: float = 1.0e-3
    rel_std_floor: Mapping[str, float] = field(default_factory=lambda: {"frequency": 1.0e-4, "damping": 0.01})
    noise_max: Mapping[str, float] = field(default_factory=lambda: {"frequency": 0.05, "damping": 0.5})
    constrained_ratio: float = 0.5
    predictive_draws: int = 500

    def __post_init__(self) -> None:
        if self.n_walkers < 16 or self.n_walkers % 2:
            raise ValueError(f"posterior.n_walkers must be even and >= 16 (2 x 8 coordinates), got {self.n_walkers}")
        if self.max_steps < 1 or self.chunk < 1:
            raise ValueError("posterior.max_steps and posterior.chunk must be >= 1")
        if self.stop_projected < 0 or self.min_chunks < 3:
            raise ValueError(f"posterior.stop_projected must be >= 0 and posterior.min_chunks >= 3, got "
                             f"{self.stop_projected} and {self.min_chunks}")
        if not 0 < self.ball < 0.1:
            raise ValueError(f"posterior.ball must lie in (0, 0.1), got {self.ball}")
        for name in ("rel_std_floor", "noise_max"):
            d = getattr(self, name)
            if set(d) != {"frequency", "damping"} or not all(v > 0 for v in d.values()):
                raise ValueError(f"posterior.{name} needs positive 'frequency' and 'damping' values, got {dict(d)}")

    @classmethod
    def from_config(cls, section: Mapping[str, Any] | None) -> PosteriorSettings:
        """Build from the config's ``posterior:`` mapping (missing keys take the defaults)."""
        section = config_section(section, (f.name for f in fields(cls)), "posterior")
        base = cls()
        for name in ("rel_std_floor", "noise_max"):
            if name in section:
                section[name] = {**getattr(base, name), **dict(section[name])}
        return cls(**section)
