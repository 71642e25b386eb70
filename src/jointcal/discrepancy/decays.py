"""Ring-downs and dwells as the discrepancy fits use them: backbone points, their scatter, the objective.

A free decay follows the model's backbone (`jointcal.models.free_decay.free_backbone`: the first harmonic
of the model with every element an effect adds, omega^2 = Re K(q) / m, zeta = Im K / (2 Re K)), so a
candidate predicts each measured point of a ring-down, f(q) and zeta(q), at its amplitude q, times the point's
read-out factor (`decay_readout`: the estimator's read-out of the candidate's simulated decay over its backbone,
taken at a reference parameter set and retaken at each optimum, as the sweeps' transient factor): near the
joint's macroslip knee f and zeta change within a window, and the validation compares the read-out, not the
backbone. The points
are the modal stage's (``backbone.csv``): every ring-down window (a dwell's own ring-down too), and each
level's dwells once by their phase resonance (``q_dwell_quad_in``, ``f_dwell_quad_hz``, ``zeta_dwell_quad``
of ``modal_properties.csv``, as the calibration takes them).

**Scatter.** Each point's relative errors are scaled by the read-out's own standard errors of f and zeta
(``f_se_hz``, ``zeta_se`` of each window, `jointcal.measure.ringdown.ringdown_backbone`, given as `se`: the
ring-downs read again as the modal stage and the validation read them), never below the sweeps' floors in the
validation's convention (`jointcal.validate.decay.scales`: 0.05 dB a relative damping of 0.58%, 0.3 deg a
relative frequency of zeta x 0.3 deg in rad): the same scale as the validation's E of the decays. Without
them (no record), the windows' scatter about a quadratic in log q per run, pooled (`read_scatter`); it takes
the backbone's curvature for noise where a run spans two decades (the virtual Ministack: 7e-4 against the
read-out's 5e-5 to 9e-5 in f).

**E.** As the validation's: the RMS of the scaled errors of f and zeta, every run weighted equally
(a ring-down counts once, however many windows it has, as in the calibration).

**Folds.** Each run is held out in turn (its level, as the sweeps' folds; a run starts from its own amplitude,
so the top run is predicted beyond the others' amplitudes). With ``bands`` > 1 each run's points are split in
log q into pieces (`DecayRun.band`) and each band across the runs is a fold too (`decay_folds`); not the
default: held out, the top third of the amplitudes is an extrapolation the hidden effect's own model makes
poorly (a cubic spring fitted below it scored 5.5 there on the virtual beam, 1.2 with the top run held out),
which capped a right name at confidence medium.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..io import level_column, level_unit
from ..io.contract import UNUSABLE
from ..io.testkinds import run_test_kind
from ..measure.testkinds import level_readout
from ..measure.testkinds.ringdown import METHOD as WINDOWS, window_top
from ..models.free_decay import free_backbone
from ..validate.decay import scales
from ..validate.testkinds import measured_read
from .decay_readout import Factor, readout_factor
from .fit import Candidate, Fit, model_at, refreshed_fit

__all__ = ["DecayRun", "DecayObjective", "decay_runs", "decay_folds", "read_scatter", "BANDS", "MIN_WINDOWS"]

BANDS = 1  # amplitude bands (equal in log q over the campaign) a run's points are split into (1: whole runs)
MIN_WINDOWS = 5  # windows a ring-down needs for its scatter about the quadratic (3 coefficients)


@dataclass(frozen=True)
class DecayRun:
    """One run's backbone points within one amplitude band (all arrays shape (n,)).

    q_in : amplitude read, in; f_hz : frequency, Hz; zeta : damping ratio; sigma_f, sigma_zeta : relative
    scatter of f and zeta; row : the manifest/modal row (run_id, its level, sequence, test); level : the
    run's level in its own unit; band : the amplitude band's label ('' for the whole run); record : the run's
    measured record (time_s, reference, response_accel_g; g), for its simulated read-out
    (`decay_readout`), None without it; read : the record's `measured_read` (the measured windows the
    validation compares with), read once; q_top : the amplitude at each window's start, in (a window reads
    from there down to q_in and beyond; None where the window lengths are not known).
    """

    q_in: NDArray[np.float64]
    f_hz: NDArray[np.float64]
    zeta: NDArray[np.float64]
    sigma_f: NDArray[np.float64]
    sigma_zeta: NDArray[np.float64]
    row: dict
    level: float = float("nan")
    band: str = ""
    record: pd.DataFrame | None = field(default=None, compare=False, repr=False)
    read: Mapping | None = field(default=None, compare=False, repr=False)
    q_top: NDArray[np.float64] | None = field(default=None, compare=False, repr=False)

    @property
    def run_id(self) -> str:
        return str(self.row["run_id"])


def read_scatter(points: Sequence[tuple[NDArray, NDArray, NDArray]]) -> tuple[float, float]:
    """Pooled relative scatter (sigma_f, sigma_zeta) of ring-down windows about a quadratic in log q per run.

    points : per run (q_in, f_hz, zeta), shape (n,) each; runs with fewer than `MIN_WINDOWS` windows are
    skipped. Returns NaN for both when no run has enough.
    """
    ss_f = ss_z = dof = 0.0
    for q, f, z in points:
        if q.size < MIN_WINDOWS:
            continue
        x = np.log(q)
        for y, acc in ((np.log(f), "f"), (np.log(z), "z")):
            r = y - np.polyval(np.polyfit(x, y, 2), x)
            if acc == "f":
                ss_f += float(r @ r)
            else:
                ss_z += float(r @ r)
        dof += q.size - 3
    if dof <= 0:
        return float("nan"), float("nan")
    return float(np.sqrt(ss_f / dof)), float(np.sqrt(ss_z / dof))


def _points(backbone: pd.DataFrame, modal: pd.DataFrame, rows: Sequence[Mapping]) -> list[tuple[dict, pd.DataFrame]]:
    """(row, its points q_in, f_hz, zeta) of each run: a ring-down's windows; each level's dwells once."""
    mrows = modal.set_index("run_id") if "run_id" in modal else pd.DataFrame()
    out, levels_done = [], set()
    bb = backbone[backbone["test"] == WINDOWS] if len(backbone) else backbone
    for row in rows:
        rid = str(row["run_id"])
        r = {**(mrows.loc[rid].to_dict() if rid in mrows.index else {}), **dict(row), "run_id": rid}
        if UNUSABLE in str(r.get("flags", "")):
            continue
        w = bb[bb["run_id"].astype(str) == rid][["q_in", "f_hz", "zeta"]].apply(pd.to_numeric, errors="coerce")
        w = w[(w > 0).all(axis=1)]
        if len(w):
            out.append((r, w.sort_values("q_in", ascending=False).reset_index(drop=True)))
        col = level_column(r)
        cols = level_readout(run_test_kind(r).name) or ()  # a dwell's: its level's phase resonance, one read-out
        quad = [float(pd.to_numeric(r.get(c), errors="coerce")) for c in cols]
        if quad and all(np.isfinite(quad)) and min(quad) > 0:
            key = (col, r.get(col))
            if key not in levels_done:  # a level's phase resonance, once for its dwells
                levels_done.add(key)
                out.append(({**r, "run_id": f"{rid}:phase_resonance"},
                            pd.DataFrame({"q_in": [quad[0]], "f_hz": [quad[1]], "zeta": [quad[2]]})))
    return out


def _window_tops(q: NDArray, f: NDArray, z: NDArray, windows: pd.DataFrame | None) -> NDArray | None:
    """The amplitude at the start of the window read at each q (in, `window_top`), the window length
    interpolated in log q along the windows read again from the record; None without their lengths."""
    if windows is None or not {"q_in", "window_s"} <= set(windows.columns):
        return None
    w = windows[(windows["q_in"] > 0) & np.isfinite(windows["window_s"])].sort_values("q_in")
    if w.empty:
        return None
    return window_top(q, f, z, np.interp(np.log(q), np.log(w["q_in"].to_numpy(float)), w["window_s"].to_numpy(float)))


def _own_se(q: NDArray, f: NDArray, z: NDArray, windows: pd.DataFrame | None) -> tuple[NDArray, NDArray] | None:
    """The read-out's relative standard errors of f and zeta at amplitudes q (interpolated in log q along the
    windows read again from the record), None without them."""
    if windows is None or not {"q_in", "f_hz", "zeta", "f_se_hz", "zeta_se"} <= set(windows.columns):
        return None
    w = windows[(windows["q_in"] > 0) & np.isfinite(windows["f_se_hz"]) & np.isfinite(windows["zeta_se"])]
    if w.empty:
        return None
    w = w.sort_values("q_in")
    lq = np.log(w["q_in"].to_numpy(float))
    at = lambda v: np.interp(np.log(q), lq, v)  # noqa: E731
    return (at((w["f_se_hz"] / w["f_hz"]).to_numpy(float)) * f,
            at((w["zeta_se"] / w["zeta"].abs()).to_numpy(float)) * z)


def decay_runs(backbone: pd.DataFrame, modal: pd.DataFrame, rows: Sequence[Mapping], *, floor_db: float = 0.05,
               floor_deg: float = 0.3, bands: int = BANDS,
               se: Mapping[str, pd.DataFrame] | None = None,
               records: Mapping[str, pd.DataFrame] | None = None) -> list[DecayRun]:
    """The assembly's backbone points as `DecayRun` pieces (each run split into amplitude bands).

    Parameters
    ----------
    backbone : DataFrame
        backbone.csv's rows (run_id, mode, test, q_in, f_hz, zeta) of this unit.
    modal : DataFrame
        modal_properties.csv's rows of this unit (flags; a dwell's phase resonance, its estimator's ``level_readout``).
    rows : sequence of mapping
        The runs' manifest rows (run_id, test, level, sequence).
    floor_db, floor_deg : float
        The validation's floors (`ValidateSettings`), in the convention of `jointcal.validate.decay.scales`.
    bands : int
        Amplitude bands, equal in log q between the campaign's smallest and largest point.
    se : mapping run_id -> DataFrame, optional
        Each ring-down's windows read again from its record (q_in, f_hz, zeta, f_se_hz, zeta_se): the
        read-out's own standard errors; a run without them takes the pooled scatter (`read_scatter`).
    records : mapping run_id -> DataFrame, optional
        Each run's measured record, kept on its pieces for the read-out factor (`decay_readout`); a dwell's
        phase resonance has none (a steady point, not a decay).
    """
    pts = _points(backbone, modal, rows)
    reads = {str(r["run_id"]): measured_read(records[str(r["run_id"])], r) for r in rows
             if str(r["run_id"]) in (records or {})}
    if not pts:
        return []
    sf, sz = read_scatter([(p["q_in"].to_numpy(), p["f_hz"].to_numpy(), p["zeta"].to_numpy()) for _, p in pts])
    lq = np.log(np.concatenate([p["q_in"].to_numpy(float) for _, p in pts]))
    edges = np.linspace(lq.min(), lq.max(), bands + 1)
    out = []
    for row, p in pts:
        q, f, z = (p[c].to_numpy(float) for c in ("q_in", "f_hz", "zeta"))
        own = _own_se(q, f, z, (se or {}).get(str(row["run_id"])))
        top = _window_tops(q, f, z, (se or {}).get(str(row["run_id"])))
        f_se, z_se = own if own is not None else (np.nan_to_num(sf) * f, np.nan_to_num(sz) * z)
        s_f, s_z = scales(pd.DataFrame({"f_hz": f, "zeta": z, "f_se_hz": f_se, "zeta_se": z_se}), floor_db=floor_db,
                          floor_deg=floor_deg)
        b = np.clip(np.digitize(np.log(q), edges[1:-1]), 0, bands - 1)
        col = level_column(row)
        for k in np.unique(b):
            i = b == k
            lo, hi = np.exp(edges[k]), np.exp(edges[k + 1])
            out.append(DecayRun(q[i], f[i], z[i], s_f[i], s_z[i], row, float(row[col]) if col else float("nan"),
                                f"q {lo:.2g} to {hi:.2g} in", (records or {}).get(str(row["run_id"])),
                                reads.get(str(row["run_id"])), None if top is None else top[i]))
    return out


def decay_folds(runs: Sequence[DecayRun]) -> dict[str, list[int]]:
    """Held-out folds: each level's runs, and each amplitude band across the runs ({} with one run)."""
    if len({r.run_id for r in runs}) < 2:
        return {}
    unit = level_unit(runs[0].row)
    levels = [r.level for r in runs]
    folds = {f"{L:g} {unit}".strip(): [i for i, v in enumerate(levels) if v == L] for L in sorted(set(levels))}
    if len(folds) < 2:
        folds = {}
    low = {}  # each band's smallest amplitude: the bands in order
    for r in runs:
        low[r.band] = min(low.get(r.band, np.inf), float(r.q_in.min()))
    bands = sorted(low, key=low.get)
    if len(bands) > 1:
        folds.update({b: [i for i, r in enumerate(runs) if r.band == b] for b in bands})
    return folds


@dataclass(frozen=True)
class DecayObjective:
    """A candidate on one assembly's backbone points, linearised at theta_ref: E, its residuals, the prediction,
    the fit.

    The model's points are its free-decay backbone at the measured amplitudes (`free_backbone`), batched over
    parameter sets, times each piece's read-out factor taken at theta_ref (`decay_readout`, R1-R2: the
    estimator's read-out of the candidate's simulated decay over its backbone). The same interface as the
    sweeps' `fit.Objective` (`at`, `subset`, `predict`, `residuals`, `E`, `fit`), so `select` scores and
    `recalibrate` recalibrates it the same way; the factor is the objective's, retaken in one place (`at`).

    Attributes
    ----------
    candidate : Candidate
    runs : tuple of DecayRun
    factor : tuple of (k_f, k_zeta) or None
        Each piece's read-out factor at theta_ref, arrays of its points' shape (None: 1, the backbone alone).
    theta_ref : ndarray or None
        Where the factors were taken (None: nowhere, every factor 1).
    """

    candidate: Candidate
    runs: tuple[DecayRun, ...]
    factor: tuple[Factor, ...] = ()
    theta_ref: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "runs", tuple(self.runs))
        if not self.factor:
            object.__setattr__(self, "factor", (None,) * len(self.runs))

    def at(self, theta: NDArray) -> DecayObjective:
        """The same candidate and points linearised at theta (n,): every piece's read-out factor taken there
        (each run's decay simulated from its record's cut and read, `decay_readout.readout_factor`)."""
        th = np.asarray(theta, dtype=float)
        if self.theta_ref is not None and np.array_equal(th, self.theta_ref):
            return self
        return DecayObjective(self.candidate, self.runs, readout_factor(self.candidate, th, self.runs), th)

    def subset(self, idx: Sequence[int]) -> DecayObjective:
        """The objective on the pieces `idx` (their factors kept)."""
        return DecayObjective(self.candidate, tuple(self.runs[i] for i in idx), tuple(self.factor[i] for i in idx),
                              self.theta_ref)

    def predict(self, theta: NDArray, i: int) -> tuple[NDArray, NDArray]:
        """Run piece i's (f Hz, zeta) at its amplitudes as the read-out shows them (R2), (P, n) or (n,)."""
        run, k = self.runs[i], self.factor[i]
        f, z = free_backbone(model_at(self.candidate, theta, run.row), run.q_in)
        return (f, z) if k is None else (f * k[0], z * k[1])

    def points(self, theta: NDArray) -> tuple[NDArray, NDArray]:
        """(f, zeta) at every piece's amplitudes, concatenated (R2): one backbone call for a model that does not
        change with the run's place in the sequence."""
        if self.candidate.sequence_dependent:
            parts = [self.predict(theta, i) for i in range(len(self.runs))]
            return np.concatenate([p[0] for p in parts], axis=-1), np.concatenate([p[1] for p in parts], axis=-1)
        q = np.concatenate([r.q_in for r in self.runs])
        f, z = free_backbone(model_at(self.candidate, theta, self.runs[0].row), q)
        if all(k is None for k in self.factor):
            return f, z
        ones = lambda r, k, j: np.ones(r.q_in.size) if k is None else k[j]  # noqa: E731
        kf = np.concatenate([ones(r, k, 0) for r, k in zip(self.runs, self.factor)])
        kz = np.concatenate([ones(r, k, 1) for r, k in zip(self.runs, self.factor)])
        return f * kf, z * kz

    def residuals(self, theta: NDArray) -> NDArray:
        """Residual vector whose sum of squares is E^2 (theta (n,) -> (m,), (P, n) -> (P, m))."""
        f_m, z_m = self.points(theta)
        cat = lambda a: np.concatenate([getattr(r, a) for r in self.runs])  # noqa: E731
        w = self.weights()[: f_m.shape[-1]]
        with np.errstate(all="ignore"):
            rf = (f_m / cat("f_hz") - 1.0) / cat("sigma_f") * w
            rz = (z_m / cat("zeta") - 1.0) / cat("sigma_zeta") * w
        r = np.concatenate([rf, rz], axis=-1)
        return np.where(np.isfinite(r), r, 1e3)

    def weights(self) -> NDArray:
        """Each residual's weight w (m,): a residual is w times its error in standard errors. Every run counts
        once, its windows equally within it, so the weights' squares sum to 1 (E 1 = errors at the scatter)."""
        ids = np.concatenate([[r.run_id] * r.q_in.size for r in self.runs])
        _, inv, count = np.unique(ids, return_inverse=True, return_counts=True)
        w = 1.0 / np.sqrt(2.0 * count[inv] * count.size)
        return np.concatenate([w, w])

    def E(self, theta: NDArray) -> float:
        return float(np.sqrt(np.sum(self.residuals(theta) ** 2)))

    def fit(self, theta0: NDArray, *, starts: int = 3, max_nfev: int = 60, free_joint: bool = True,
            refresh: int = 0) -> Fit:
        """Bounded least squares over the candidate's unit cube, as `fit.Objective.fit`.

        refresh : times the read-out factor is retaken (at theta0 first, then at each optimum, refitting from
        it); 0 keeps this objective's factors.
        """
        return refreshed_fit(self, theta0, starts, max_nfev, free_joint, refresh)
