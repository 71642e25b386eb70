"""The ``calibrate:`` config section as a frozen settings object, with its defaults.

The defaults equal ``workflow/config/config.yaml``. Bounds are wide enough for
rigs other than the Ministack (the GA searches them log-uniformly):

==========  ==================  ====================================================
parameter   bounds              reasoning
==========  ==================  ====================================================
Fs          1 .. 1e4 lbf        from a finger-tight fastener to a heavily preloaded
                                press fit (Table 3.2: 274-313 lbf at 700 lbf preload)
KT          1e4 .. 1e8 lbf/in   with the 2.65 lbf slug: stuck frequencies 190 Hz to 19 kHz
chi         -0.95 .. 0          Segalman's range (-1, 0]; chi -> -1 makes R vanish
beta        1e-4 .. 5           log-scaled; below 1e-4 no different from 0 (space.py)
k           1e4 .. 1e8 lbf/in   as KT: the path around the joint can dominate either way
zeta_v      1e-4 .. 0.1         0.01% (metal) to 10% (elastomer) viscous damping
==========  ==================  ====================================================
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, Literal

from ..models import G
from .data import DAMPING
from .ga import GAOptions
from .objective import MODELS
from .space import ParamSpace

__all__ = ["DEFAULT_BOUNDS", "CalibrateSettings"]

DEFAULT_BOUNDS: dict[str, list[float]] = {
    "Fs": [1.0, 1.0e4], "KT": [1.0e4, 1.0e8], "chi": [-0.95, 0.0],
    "beta": [1.0e-4, 5.0], "k": [1.0e4, 1.0e8], "zeta_v": [1.0e-4, 0.1],
}
_GA_KEYS = {f.name for f in fields(GAOptions)}


@dataclass(frozen=True)
class CalibrateSettings:
    """Settings of the calibration stage (see ``workflow/config/config.yaml``).

    model : 'harmonic_balance' or 'qsma'; viscous : 'dashpot' or 'constant' (convention of
    zeta_v, `jointcal.calibrate.objective`); damping : the modal column fitted; eta : the
    frequency weight of eq. 3.9; slug_weight_lbf : slug weight, lbf (m = weight / g);
    bounds : {name: [lower, upper]}; ga : GAOptions (seed included); n_polish : number of
    distinct good GA individuals refined by bounded least squares (0: none); curve_points,
    curve_widen : the amplitude grid of model_curves.csv (points; factor beyond the
    measured range on each side).
    """

    model: Literal["harmonic_balance", "qsma"] = "harmonic_balance"
    viscous: Literal["dashpot", "constant"] = "dashpot"
    damping: str = "zeta_phase_resonance"
    eta: float = 0.85
    slug_weight_lbf: float = 2.65
    bounds: Mapping[str, Any] = field(default_factory=lambda: dict(DEFAULT_BOUNDS))
    ga: GAOptions = GAOptions()
    n_polish: int = 8
    curve_points: int = 200
    curve_widen: float = 3.0

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise ValueError(f"calibrate.model must be one of {', '.join(MODELS)}, got {self.model!r}")
        if self.viscous not in ("dashpot", "constant"):
            raise ValueError(f"calibrate.viscous must be 'dashpot' or 'constant', got {self.viscous!r}")
        if self.damping not in DAMPING:
            raise ValueError(f"calibrate.damping must be one of {', '.join(DAMPING)}, got {self.damping!r}")
        if not 0.0 <= self.eta <= 1.0:
            raise ValueError(f"calibrate.eta must lie in [0, 1], got {self.eta!r}")
        if not self.slug_weight_lbf > 0:
            raise ValueError(f"calibrate.slug_weight_lbf must be positive, got {self.slug_weight_lbf!r}")
        if self.n_polish < 0:
            raise ValueError(f"calibrate.n_polish must be >= 0, got {self.n_polish!r}")
        if self.curve_points < 2 or self.curve_widen < 1:
            raise ValueError("calibrate.curve_points must be >= 2 and curve_widen >= 1")
        self.space  # validates the bounds

    @property
    def m(self) -> float:
        """Slug mass, lbf s^2/in."""
        return self.slug_weight_lbf / G

    @property
    def space(self) -> ParamSpace:
        """The bounded parameter space."""
        return ParamSpace.from_bounds(self.bounds)

    @classmethod
    def from_config(cls, section: Mapping[str, Any] | None) -> CalibrateSettings:
        """Build from the config's ``calibrate:`` mapping (missing keys take the defaults).

        GA keys (population, offspring, generations, cxpb, mutpb, sbx_eta, sigma_max,
        sigma_min, sigma_scale, indpb, tournament, elite, stall_generations, stall_rtol,
        checkpoint_every, seed) sit at the top level of the section.
        """
        section = dict(section or {})
        own = {f.name for f in fields(cls)} - {"ga"}
        unknown = sorted(set(section) - own - _GA_KEYS)
        if unknown:
            raise ValueError(f"calibrate: unknown key(s) {', '.join(unknown)}")
        ga = GAOptions(**{k: section.pop(k) for k in list(section) if k in _GA_KEYS})
        bounds = {**DEFAULT_BOUNDS, **dict(section.pop("bounds", {}) or {})}
        bounds = {k: [float(x) for x in v] for k, v in bounds.items()}
        return cls(ga=ga, bounds=bounds, **section)
