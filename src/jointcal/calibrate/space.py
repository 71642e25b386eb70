"""The calibration's parameter space: six joint parameters, bounds and their scaling.

The GA's genes and the posterior's coordinates are the same normalised space u in
[0, 1]^6 (one column per parameter in `PARAMS` order). A positive scale parameter
(Fs, KT, k, zeta_v) and the shape ratio beta are mapped logarithmically between their
bounds, chi linearly:

    x = log10(p) (log) or p (linear);  u = (x - x_lo) / (x_hi - x_lo).

beta is log-scaled with a small positive floor (default 1e-4) rather than linear in
[0, beta_max]: the paper's values (0.004, 0.025) are an order of magnitude apart, and a
log scale gives each decade the same prior mass and GA resolution. beta below the floor
is indistinguishable from 0: c = beta + (chi+1)/(chi+2) >= 0.048 for chi >= -0.95, so
beta = 1e-4 changes c, phi_max, R and S by at most 0.2% (eqs. 3.5-3.7).

The space grows by a named effect's parameters (`ParamSpace.grow`): the
discrepancy workflow's candidate models are the six joint columns followed by the
effect's own, each with its bounds and scaling, and the GA and the sampler work on the
grown unit cube unchanged.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["PARAMS", "UNITS", "LOG_SCALED", "ParamSpace"]

PARAMS: tuple[str, ...] = ("Fs", "KT", "chi", "beta", "k", "zeta_v")
UNITS: dict[str, str] = {"Fs": "lbf", "KT": "lbf/in", "chi": "-", "beta": "-", "k": "lbf/in", "zeta_v": "-"}
LOG_SCALED: dict[str, bool] = {"Fs": True, "KT": True, "chi": False, "beta": True, "k": True, "zeta_v": True}


@dataclass(frozen=True)
class ParamSpace:
    """Bounds of (Fs, KT, chi, beta, k, zeta_v) -- and of any parameters grown onto them --
    and the map to the unit cube.

    Parameters
    ----------
    lo, hi : tuple of float, length n
        Lower and upper bounds in physical units (lbf, lbf/in, -, -, lbf/in, -, then the
        grown parameters' units), in `names` order. Log-scaled parameters need
        0 < lo < hi; chi needs -1 < lo < hi <= 0.
    names : tuple of str
        Column names; default the paper's six `PARAMS`.
    log : tuple of bool, optional
        Log10 scaling per column; default `LOG_SCALED` (required for other names).
    """

    lo: tuple[float, ...]
    hi: tuple[float, ...]
    names: tuple[str, ...] = PARAMS
    log: tuple[bool, ...] | None = None

    def __post_init__(self) -> None:
        if self.log is None:
            unknown = [p for p in self.names if p not in LOG_SCALED]
            if unknown:
                raise ValueError(f"parameter(s) {', '.join(unknown)}: give their scaling (log=...)")
            object.__setattr__(self, "log", tuple(LOG_SCALED[p] for p in self.names))
        n = len(self.names)
        if len(set(self.names)) != n:
            raise ValueError(f"parameter names repeat: {', '.join(self.names)}")
        if len(self.lo) != n or len(self.hi) != n or len(self.log) != n:
            raise ValueError(f"bounds need {n} values each ({', '.join(self.names)}), "
                             f"got {len(self.lo)} and {len(self.hi)}")
        for name, a, b, lg in zip(self.names, self.lo, self.hi, self.log):
            if not (np.isfinite(a) and np.isfinite(b) and a < b):
                raise ValueError(f"bounds of {name}: need finite lower < upper, got [{a!r}, {b!r}]")
            if lg and a <= 0:
                raise ValueError(f"bounds of {name}: it is log-scaled, so the lower bound must be > 0, got {a!r}")
        if "chi" in self.names:
            chi = self.names.index("chi")
            if not (-1.0 < self.lo[chi] and self.hi[chi] <= 0.0):
                raise ValueError(f"bounds of chi must lie in (-1, 0], got [{self.lo[chi]!r}, {self.hi[chi]!r}]")

    def grow(self, names: Sequence[str], lo: Sequence[float], hi: Sequence[float],
             log: Sequence[bool]) -> ParamSpace:
        """This space with further parameters appended (an effect's: names, bounds, scaling)."""
        return ParamSpace((*self.lo, *map(float, lo)), (*self.hi, *map(float, hi)), (*self.names, *names),
                          (*self.log, *map(bool, log)))

    @classmethod
    def from_bounds(cls, bounds: Mapping[str, ArrayLike]) -> ParamSpace:
        """Build from a mapping ``{name: [lower, upper]}`` (the config's ``bounds``)."""
        missing = [p for p in PARAMS if p not in bounds]
        extra = [p for p in bounds if p not in PARAMS]
        if missing or extra:
            raise ValueError(f"bounds must name exactly {', '.join(PARAMS)} "
                             f"(missing: {', '.join(missing) or 'none'}; unknown: {', '.join(extra) or 'none'})")
        pairs = [tuple(float(v) for v in bounds[p]) for p in PARAMS]
        if any(len(p) != 2 for p in pairs):
            raise ValueError("each bound must be a [lower, upper] pair")
        return cls(tuple(p[0] for p in pairs), tuple(p[1] for p in pairs))

    @property
    def ndim(self) -> int:
        """Number of parameters (6 for the paper's joint)."""
        return len(self.names)

    @property
    def is_log(self) -> NDArray[np.bool_]:
        """Which parameters are log10-scaled, shape (n,)."""
        return np.array(self.log, dtype=bool)

    @property
    def x_lo(self) -> NDArray[np.float64]:
        """Lower bounds in the sampling space x (log10 or linear), shape (n,)."""
        return np.array([np.log10(v) if lg else v for lg, v in zip(self.log, self.lo)])

    @property
    def x_hi(self) -> NDArray[np.float64]:
        """Upper bounds in the sampling space x, shape (n,)."""
        return np.array([np.log10(v) if lg else v for lg, v in zip(self.log, self.hi)])

    @property
    def x_names(self) -> tuple[str, ...]:
        """Names of the sampling-space coordinates, e.g. ``log10_Fs`` and ``chi``."""
        return tuple(f"log10_{p}" if lg else p for p, lg in zip(self.names, self.log))

    def to_physical(self, u: ArrayLike) -> NDArray[np.float64]:
        """Unit-cube coordinates (..., n) to physical parameters (..., n)."""
        x = self.x_lo + np.asarray(u, dtype=float) * (self.x_hi - self.x_lo)
        return np.where(self.is_log, 10.0 ** np.where(self.is_log, x, 0.0), x)  # no power of a linear column

    def to_unit(self, p: ArrayLike) -> NDArray[np.float64]:
        """Physical parameters (..., n) to unit-cube coordinates (..., n) (not clipped)."""
        p = np.asarray(p, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.where(self.is_log, np.log10(np.where(p > 0, p, np.nan)), p)
        return (x - self.x_lo) / (self.x_hi - self.x_lo)

    def unit_to_x(self, u: ArrayLike) -> NDArray[np.float64]:
        """Unit-cube coordinates to the sampling space x (log10 or linear)."""
        return self.x_lo + np.asarray(u, dtype=float) * (self.x_hi - self.x_lo)

    def inside(self, u: ArrayLike) -> NDArray[np.bool_]:
        """True where a point (..., n) of the unit cube lies within the bounds (and is finite)."""
        u = np.asarray(u, dtype=float)
        return np.all(np.isfinite(u) & (u >= 0.0) & (u <= 1.0), axis=-1)
