"""The ``calibrate:`` config section as a frozen settings object, with its defaults.

The defaults equal ``workflow/config/config.yaml`` (whose ``model_kind`` is ``auto``:
`jointcal.calibrate.kind`). The Ministack kind's bounds, `DEFAULT_BOUNDS`, are wide enough
for rigs other than the Ministack (the GA searches them log-uniformly); the modal kind's
come from the data (`jointcal.calibrate.kind.data_bounds`); ``bounds`` in the config
override either, parameter by parameter:

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

from ..units import G
from .data import DAMPING
from .ga import GAOptions
from .kind import KINDS
from .objective import MODELS
from .space import PARAMS, ParamSpace
from .._config import config_section

__all__ = ["DEFAULT_BOUNDS", "JOINT", "CalibrateSettings"]

DEFAULT_BOUNDS: dict[str, list[float]] = {
    "Fs": [1.0, 1.0e4], "KT": [1.0e4, 1.0e8], "chi": [-0.95, 0.0],
    "beta": [1.0e-4, 5.0], "k": [1.0e4, 1.0e8], "zeta_v": [1.0e-4, 0.1],
}
_GA_KEYS = {f.name for f in fields(GAOptions)}
JOINT = ParamSpace.from_bounds(DEFAULT_BOUNDS)  # the joint's six columns (names, units, scaling) at the defaults


@dataclass(frozen=True)
class CalibrateSettings:
    """Settings of the calibration stage (see ``workflow/config/config.yaml``).

    model : 'harmonic_balance' or 'qsma'; viscous : 'dashpot' or 'constant' (convention of
    zeta_v, `jointcal.calibrate.objective`); damping : the modal column fitted (zeta_res:
    the damping of each run's own read-out); eta : the frequency weight of eq. 3.9;
    model_kind : 'ministack', 'modal' or 'auto' (`jointcal.calibrate.kind`: 'auto' is
    resolved against the modal table by `resolve`); slug_weight_lbf : slug weight, lbf
    (ministack: m = weight / g); modal_mass : the mode's modal mass, lbf s^2/in (modal; None:
    per unit modal mass, m = 1); bounds : {name: [lower, upper]}, the config's overrides of
    the kind's defaults (after `resolve`, all six); ga : GAOptions (seed included); n_polish : number of
    distinct good GA individuals refined by bounded least squares (0: none); curve_points,
    curve_widen : the amplitude grid of model_curves.csv (points; factor beyond the
    measured range on each side).
    """

    model: Literal["harmonic_balance", "qsma"] = "harmonic_balance"
    viscous: Literal["dashpot", "constant"] = "dashpot"
    damping: str = "zeta_res"
    eta: float = 0.85
    model_kind: str = "ministack"
    slug_weight_lbf: float = 2.65
    modal_mass: float | None = None
    bounds: Mapping[str, Any] = field(default_factory=dict)
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
        if self.model_kind not in KINDS:
            raise ValueError(f"calibrate.model_kind must be one of {', '.join(KINDS)}, got {self.model_kind!r}")
        if self.modal_mass is not None and not self.modal_mass > 0:
            raise ValueError(f"calibrate.modal_mass must be positive (lbf s^2/in) or null, got {self.modal_mass!r}")
        unknown = sorted(set(self.bounds) - set(PARAMS))
        if unknown:
            raise ValueError(f"calibrate.bounds: unknown parameter(s) {', '.join(unknown)}; they are "
                             f"{', '.join(PARAMS)}")
        if self.n_polish < 0:
            raise ValueError(f"calibrate.n_polish must be >= 0, got {self.n_polish!r}")
        if self.curve_points < 2 or self.curve_widen < 1:
            raise ValueError("calibrate.curve_points must be >= 2 and curve_widen >= 1")
        if self.model_kind == "ministack" or set(self.bounds) == set(PARAMS):
            self.space  # validates the bounds

    @property
    def m(self) -> float:
        """The moving mass, lbf s^2/in: the slug's (ministack), the given modal mass or 1 (modal)."""
        if self.model_kind == "modal":
            return 1.0 if self.modal_mass is None else float(self.modal_mass)
        return self.slug_weight_lbf / G

    @property
    def space(self) -> ParamSpace:
        """The bounded parameter space: the config's bounds over the Ministack's defaults, or (modal) the
        bounds `resolve` took from the data."""
        if self.model_kind == "ministack":
            return ParamSpace.from_bounds({**DEFAULT_BOUNDS, **self.bounds})
        if set(self.bounds) != set(PARAMS):
            raise ValueError(f"calibrate: the {self.model_kind} model's bounds come from the data; resolve the "
                             "settings against the modal table (jointcal.calibrate.resolve) or the calibration's "
                             "ga_best.json (CalibrateSettings.resolved) first.")
        return ParamSpace.from_bounds(self.bounds)

    @property
    def full_bounds(self) -> dict[str, list[float]]:
        """All six bounds, {name: [lower, upper]} (physical units)."""
        sp = self.space
        return {n: [float(a), float(b)] for n, a, b in zip(sp.names, sp.lo, sp.hi)}

    def resolved(self, best: Mapping[str, Any]) -> CalibrateSettings:
        """These settings as the calibration that wrote ``best`` (its ga_best.json) resolved them: model
        kind, mass and all six bounds (a ga_best.json from before model kinds: the Ministack's)."""
        from dataclasses import replace

        kind = best.get("model_kind", "ministack")
        bounds = best.get("bounds") or {**DEFAULT_BOUNDS, **self.bounds}
        mass = None if best.get("per_unit_modal_mass", True) else best.get("m")
        return replace(self, model_kind=kind, bounds={k: list(map(float, v)) for k, v in bounds.items()},
                       modal_mass=mass if kind == "modal" else self.modal_mass)

    @classmethod
    def from_config(cls, section: Mapping[str, Any] | None) -> CalibrateSettings:
        """Build from the config's ``calibrate:`` mapping (missing keys take the defaults).

        GA keys (population, offspring, generations, cxpb, mutpb, sbx_eta, sigma_max,
        sigma_min, sigma_scale, indpb, tournament, elite, stall_generations, stall_rtol,
        checkpoint_every, seed) sit at the top level of the section.
        """
        section = config_section(section, ({f.name for f in fields(cls)} - {"ga"}) | _GA_KEYS, "calibrate")
        ga = GAOptions(**{k: section.pop(k) for k in list(section) if k in _GA_KEYS})
        bounds = {k: [float(x) for x in v] for k, v in dict(section.pop("bounds", {}) or {}).items()}
        return cls(ga=ga, bounds=bounds, **section)
