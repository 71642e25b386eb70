"""The interface every effect module fills: its parameters, how it changes the model, its fingerprint, advice.

An effect is physics a calibrated joint model may be missing. `Effect` holds:

* ``params``: its parameters (`EffectParam`: name, unit, bounds, log scaling, the start of a
  fit, meaning); a calibration space grows by them (`jointcal.calibrate.space.ParamSpace`);
* ``apply(model, values, row) -> model``: the `MinistackModel` with the effect at the
  parameter ``values`` for the run of manifest ``row`` (its ``sequence``, for an effect that
  changes over the test series). It may change the structure (a field such as
  ``fixture``), the sensor (``sensor_gain``, ``sensor_delay_s``), the joint, or add a
  nonlinear element (`jointcal.models.elements`): the envelope model and the time
  simulation then both see it, with no change of theirs;
* ``fingerprint(fp, sigma_db, sigma_f) -> (seen, words)``: whether the fingerprint
  features of the baseline's residuals (`jointcal.discrepancy.fingerprints`) point at it,
  with sigma_db the repeat scatter of the magnitude (dB) and sigma_f the relative repeat
  scatter of the resonance frequency, and the evidence in words;
* ``advice(values) -> str``: what to check in the lab, in words;
* ``hidden``: the strength at which the virtual lab (`jointcal.synth`) hides it by default;
* ``library``: whether the discrepancy workflow tries it (an effect kept out on purpose tests
  the workflow's 'unexplained');
* ``rescale``: the ranges of its parameters for another structure than the Ministack, from its
  stuck stiffness K0, frequency f0 and largest amplitude q (a cubic spring's range follows
  K0 / q^2, a delay's the period);
* ``kinds``: the model kinds (`jointcal.calibrate.kind`) whose discrepancy library holds it:
  ``ministack`` (the base-driven rig) and ``modal`` (one mode of any structure, force- or
  voltage-driven). An effect that applies to both lives once.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from ..models import MinistackModel

__all__ = ["EffectParam", "Effect"]

Fingerprint = Callable[[Mapping[str, "float | None"], float, float], "tuple[bool, str]"]


@dataclass(frozen=True)
class EffectParam:
    """One parameter of an effect: name, unit, bounds lo..hi, log scaling, start value of a fit and meaning;
    grid: points of an even grid over its range (in the fits' unit cube: log-spaced on a log scale) where a fit
    first evaluates the misfit and also starts from the best (0: none), for a parameter whose misfit has
    many valleys, such as a frequency (`jointcal.discrepancy.fit.least_squares_fit`)."""

    name: str
    unit: str
    lo: float
    hi: float
    log: bool
    start: float
    meaning: str
    grid: int = 0
    voltage: bool = False  # only on a voltage-driven campaign's sweeps (the shaker's loop: scales["voltage"])

    def __post_init__(self) -> None:
        if self.grid < 0 or self.grid == 1:
            raise ValueError(f"effect parameter {self.name}: grid is 0 (none) or at least 2 points, got {self.grid!r}.")
        if not (self.lo < self.hi and self.lo <= self.start <= self.hi) or (self.log and self.lo <= 0):
            raise ValueError(f"effect parameter {self.name}: need lo < hi, lo <= start <= hi and lo > 0 on a log "
                             f"scale, got lo={self.lo!r}, hi={self.hi!r}, start={self.start!r}, log={self.log!r}.")


@dataclass(frozen=True)
class Effect:
    """A named effect (see the module notes for each field)."""

    name: str
    params: tuple[EffectParam, ...]
    apply: Callable[[MinistackModel, Mapping[str, float], Mapping], MinistackModel]
    advice: Callable[[Mapping[str, float]], str]
    fingerprint: Fingerprint | None = None
    hidden: Mapping[str, float] | None = None  # None: the parameters' start values
    sequence_dependent: bool = False  # the model changes with the run's place in the test sequence (apply reads
    # its row); False: one model serves every run of a parameter set (the discrepancy fits build it once)
    library: bool = True
    summary: str = ""  # what it is, in a line
    kinds: tuple[str, ...] = ("ministack", "modal")
    # ranges of its parameters for another structure: scales {K0 lbf/in, f0 Hz, q in} -> {name: (lo, hi, start)}
    rescale: Callable[[Mapping[str, float]], Mapping[str, tuple[float, float, float]]] | None = None

    def __post_init__(self) -> None:
        names = [p.name for p in self.params]
        if not names or len(set(names)) != len(names):
            raise ValueError(f"effect {self.name}: needs one or more distinct parameter names, got {names}.")
        if self.hidden is not None and set(self.hidden) != set(names):
            raise ValueError(f"effect {self.name}: hidden defaults {sorted(self.hidden)} must name exactly its "
                             f"parameters {sorted(names)}.")

    def params_for(self, scales: Mapping[str, float] | None = None) -> tuple[EffectParam, ...]:
        """Its parameters, their ranges and starts set by `rescale` for a structure of the given scales
        (none given, or no `rescale`: the library's own, the Ministack's); a `EffectParam.voltage` one only
        where the scales say the sweeps are voltage-driven (``scales["voltage"]``)."""
        params = tuple(p for p in self.params if not p.voltage or (scales or {}).get("voltage"))
        if not scales or self.rescale is None:
            return params
        new = self.rescale(scales)
        return tuple(replace(p, lo=new[p.name][0], hi=new[p.name][1], start=new[p.name][2]) if p.name in new else p
                     for p in params)

    @property
    def defaults(self) -> dict[str, float]:
        """The hidden strength the virtual lab uses when a spec gives no value."""
        return dict(self.hidden) if self.hidden is not None else {p.name: p.start for p in self.params}
