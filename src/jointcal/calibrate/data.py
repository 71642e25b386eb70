"""The calibration's input: one assembly's usable runs from the modal stage's tables.

Reads ``modal_properties.csv`` (one row per run: ``run_id, assembly, q_in, f_res_hz``,
the damping column named in the config, ``flags``; ``level_g`` or ``level_lbf`` is
carried along when present), ``scatter.csv``
(tidy repeatability: ``assembly, quantity, level_g, source, n, mean, std, rel_std``) and, when
given, ``backbone.csv``: a ring-down then gives every window along its decay and a level's dwells
their phase resonance, each read-out weighted once (`jointcal.calibrate._readouts`; without it,
and for swept runs, one point per run of weight 1 as before).
Rows whose ``flags`` name ``unusable``, or an ingest flag of wrong units or level,
swapped channels, a constant channel or clipping (`jointcal.io.UNUSABLE_FLAGS`),
are left out; other flags are informational.
The pooled relative scatter of the frequency and of the chosen damping estimator is the
likelihood's noise floor; a missing, zero or tiny pooled value is replaced by a floor
from the config, and the replacement is reported in `ModalData.notes`. Every problem
raises `CalibrationInputError` with one sentence naming the file, the problem and the fix.
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, NoReturn

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from jointcal.io import UNUSABLE_FLAGS, level_column
from jointcal.io.contract import UNUSABLE

from ..measure.testkinds import methods
from ._readouts import expand

__all__ = ["CalibrationInputError", "ModalData", "DAMPING", "select_modal", "read_modal", "read_table",
           "read_backbone", "BACKBONE_COLUMNS"]

Damping = Literal["zeta_res", "zeta_phase_resonance", "zeta_half_power"]
DAMPING: tuple[str, ...] = ("zeta_res", "zeta_phase_resonance", "zeta_half_power")
FREQUENCY = "f_res_hz"
_MODAL_COLUMNS = ("run_id", "assembly", "q_in", FREQUENCY, "flags")
_READOUT_COLUMNS = ("q_in", FREQUENCY)
_SCATTER_COLUMNS = ("assembly", "quantity", "source", "rel_std")
BACKBONE_COLUMNS = ("run_id", "mode", "test", "q_in", "f_hz", "zeta")  # jointcal.measure.testkinds


class CalibrationInputError(ValueError):
    """A calibration input table breaks its contract (one sentence: file, problem, fix)."""


def _fail(where: object, problem: str, fix: str) -> NoReturn:
    raise CalibrationInputError(f"{where}: {problem}; {fix}.")


@dataclass(frozen=True)
class ModalData:
    """One assembly's measured resonances (usable runs only, in file order).

    Attributes
    ----------
    assembly : str
    run_id : tuple of str, length N
    level : ndarray, shape (N,) -- drive level (g; lbf or V for force- or voltage-driven runs); NaN
        when the table has no level column.
    q : ndarray, shape (N,) -- amplitude the read-out belongs to (q_in), in: the joint's relative
        displacement at resonance (base-driven), the mode's largest displacement (force, voltage).
    f : ndarray, shape (N,) -- resonance frequency, Hz.
    zeta : ndarray, shape (N,) -- damping ratio (0.02, not 2%) from ``damping``.
    damping : str -- the damping column used.
    rel_noise : (float, float) -- relative noise scale of f and zeta (pooled scatter,
        floored); NaN when no scatter table was read.
    notes : tuple of str -- exclusions and floors applied, for the log.
    weight : ndarray, shape (N,), or None -- each point's weight in eq. 3.9 and the likelihood (a
        ring-down's k windows 1/k each: `jointcal.calibrate._readouts`); None: 1 each.
    sigma : (ndarray, ndarray), each shape (N,), or None -- each point's own relative standard error of f
        and of zeta (a ring-down window's read-out, floored as the validation floors it:
        `jointcal.measure.testkinds.ringdown.window_scales`); set when every point has them (a campaign
        of ring-downs alone, read with backbone.csv's ``f_se_hz`` and ``zeta_se``), and in a campaign of test
        kinds alone (ring-downs and dwells, no sweep) where some points have them: a level of dwells' phase
        resonance, which has none, then carries the noise floors (`floors`); None otherwise (sweeps keep
        eq. 3.9's relative errors).
    q_top : ndarray, shape (N,), or None -- with `sigma`: the amplitude at each window's start, in (the
        largest its read-out spans).

    The arrays hold one entry per point: per run, or per ring-down window and level of dwells when
    the points came from backbone.csv (``run_id`` then repeats a run, or joins a level's dwells).
    """

    assembly: str
    run_id: tuple[str, ...]
    level: NDArray[np.float64]
    q: NDArray[np.float64]
    f: NDArray[np.float64]
    zeta: NDArray[np.float64]
    damping: str
    rel_noise: tuple[float, float]
    notes: tuple[str, ...]
    weight: NDArray[np.float64] | None = None
    sigma: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
    q_top: NDArray[np.float64] | None = None

    @property
    def w(self) -> NDArray[np.float64]:
        """The points' weights, shape (N,): `weight`, or ones."""
        return np.ones(self.q.size) if self.weight is None else np.asarray(self.weight, dtype=float)

    @property
    def n_readouts(self) -> float:
        """The number of read-outs, sum(w): the N of eq. 3.9 (the number of points when all weigh 1)."""
        return float(self.q.size) if self.weight is None else float(np.sum(self.weight))


def _usable(flags: pd.Series) -> NDArray[np.bool_]:
    """False for runs flagged unusable or with an ingest flag in UNUSABLE_FLAGS (units, level, channels, clipping)."""
    text = flags.map(lambda v: "" if pd.isna(v) else str(v))
    return ~text.map(lambda t: any(UNUSABLE in tok.strip().lower()
                                   or tok.strip().split(":")[0] in UNUSABLE_FLAGS for tok in t.split(";"))
                     ).to_numpy(bool)


def _pooled(scatter: pd.DataFrame, assembly: str, quantity: str, floor: float, where: object,
            notes: list[str]) -> float:
    rows = scatter[(scatter["assembly"].astype(str) == assembly) & (scatter["quantity"] == quantity)
                   & (scatter["source"] == "pooled")]
    value = pd.to_numeric(rows["rel_std"], errors="coerce").to_numpy(float)
    value = value[np.isfinite(value)]
    if value.size == 0 or value[0] <= 0:
        notes.append(f"{where}: no positive pooled rel_std of {quantity} for assembly {assembly!r}; "
                     f"using the floor {floor:g}")
        return float(floor)
    if value[0] < floor:
        notes.append(f"{where}: pooled rel_std of {quantity} for assembly {assembly!r} is {value[0]:.3g}, "
                     f"below the floor; using {floor:g}")
        return float(floor)
    return float(value[0])


def select_modal(modal: pd.DataFrame, assembly: str, *, damping: Damping = "zeta_res",
                 scatter: pd.DataFrame | None = None, floors: Mapping[str, float] | None = None,
                 modal_name: object = "modal_properties.csv", scatter_name: object = "scatter.csv",
                 backbone: pd.DataFrame | None = None, backbone_name: object = "backbone.csv") -> ModalData:
    """Validate the modal tables and return one assembly's usable runs.

    Parameters
    ----------
    modal : pandas.DataFrame
        The modal-properties table (see module notes).
    assembly : str
        Assembly to select.
    damping : {'zeta_res', 'zeta_phase_resonance', 'zeta_half_power'}
        Damping estimator: zeta_res, the damping of each run's own read-out (the phase-resonance
        energy balance for base-driven runs, the swept-mode fit's for force- and voltage-driven
        ones); half power reproduces the paper.
    scatter : pandas.DataFrame, optional
        The scatter table; without it ``rel_noise`` is (NaN, NaN).
    floors : mapping, optional
        ``{'frequency': 1e-4, 'damping': 0.01}``: smallest relative noise scales.
    backbone : pandas.DataFrame, optional
        backbone.csv: with it, ring-down and dwell runs give their points (`jointcal.calibrate._readouts`).
    modal_name, scatter_name, backbone_name : object
        How the files are named in error messages and notes.

    Returns
    -------
    ModalData

    Raises
    ------
    CalibrationInputError
        Missing column, unknown assembly, every run flagged unusable, or no usable run with
        positive q_in, f_res_hz and damping (a run lacking one of them is left out, with a note).
    """
    if damping not in DAMPING:
        raise ValueError(f"damping must be one of {', '.join(DAMPING)}, got {damping!r}")

    def _need(columns) -> None:
        missing = [c for c in columns if c not in modal.columns]
        if missing:
            _fail(modal_name, f"column(s) {', '.join(missing)} missing (found: "
                  f"{', '.join(map(str, modal.columns))})", "regenerate it with the modal stage")

    # the read-outs' columns after the flags: a table whose every run is unusable may have none of them (the modal
    # stage read nothing), and what to fix is then the runs, which the modal log names
    _need([c for c in _MODAL_COLUMNS if c not in _READOUT_COLUMNS])
    rows = modal[modal["assembly"].astype(str) == str(assembly)]
    if rows.empty:
        found = ", ".join(sorted(map(str, modal["assembly"].unique()))) or "none"
        _fail(modal_name, f"it has no runs of assembly {assembly!r} (assemblies: {found})",
              "check the assembly name or rerun the modal stage")
    keep = _usable(rows["flags"])
    notes = [f"{modal_name}: {int((~keep).sum())} of {len(rows)} runs of {assembly!r} flagged unusable, left out"]
    if not keep.any():
        _fail(modal_name, f"all {len(rows)} runs of assembly {assembly!r} are flagged unusable",
              "fix the flagged runs or the modal settings (the modal stage's log says why each run was flagged); "
              "nothing is left to calibrate")
    _need([*_READOUT_COLUMNS, damping])
    rows = rows[keep]
    finite = np.ones(len(rows), bool)
    for col in ("q_in", FREQUENCY, damping):
        v = pd.to_numeric(rows[col], errors="coerce").to_numpy(float)
        finite &= np.isfinite(v) & (v > 0)
    if not finite.all():  # a run without this read-out (e.g. no phase-resonance damping): left out, said why
        for _, r in rows[~finite].iterrows():
            notes.append(f"{modal_name}: run {r['run_id']!r} has no positive q_in, {FREQUENCY} and {damping} "
                         f"(method {r.get('f_res_method', '?')}, flags {r.get('flags', '') or 'none'}); left out")
    if not finite.any():
        other = [c for c in DAMPING if c != damping and c in rows.columns
                 and (pd.to_numeric(rows[c], errors="coerce") > 0).any()]
        why = (" (a voltage is not a force: no phase-resonance damping)" if damping == "zeta_phase_resonance"
               and "level_V" in rows.columns else "")
        _fail(modal_name, f"no usable run of assembly {assembly!r} has a positive q_in, {FREQUENCY} and "
              f"{damping}{why}", f"set calibrate.damping to {other[0]}" if other
              else "rerun the modal stage, or check the flags and sweep_note of its runs")
    rows = rows[finite]
    values = {col: pd.to_numeric(rows[col], errors="coerce").to_numpy(float) for col in ("q_in", FREQUENCY, damping)}
    level_col = level_column(rows.columns)
    level = (np.full(len(rows), np.nan) if level_col is None
             else pd.to_numeric(rows[level_col], errors="coerce").to_numpy(float))
    floors = {"frequency": 1e-4, "damping": 0.01, **(floors or {})}
    run_id, weight, sigma, q_top = tuple(map(str, rows["run_id"])), None, None, None
    method = rows["f_res_method"].astype(str) if "f_res_method" in rows else pd.Series([], dtype=str)
    if backbone is not None and method.isin(methods()).any():  # a test kind's read-outs: its points in backbone
        missing = [c for c in BACKBONE_COLUMNS if c not in backbone.columns]
        if missing:
            _fail(backbone_name, f"column(s) {', '.join(missing)} missing (found: "
                  f"{', '.join(map(str, backbone.columns))})", "regenerate it with the modal stage")
        pts, more = expand(rows, backbone, level, ("q_in", FREQUENCY, damping), backbone_name)
        notes += more
        run_id, level, weight = tuple(map(str, pts["run_id"])), pts["level"], pts["weight"]
        own = np.isfinite(pts["sigma_f"]) & np.isfinite(pts["sigma_zeta"]) & np.isfinite(pts["q_top"])
        if own.all() or (own.any() and method.isin(methods()).all()):  # the polish's scale (`calibrate.fit`):
            # the windows' own standard errors; a level of dwells' phase resonance (test kinds alone) at the floors
            sigma = (np.where(own, pts["sigma_f"], floors["frequency"]), np.where(own, pts["sigma_zeta"],
                                                                                  floors["damping"]))
            q_top = np.where(own, pts["q_top"], pts["q"])
        values = {"q_in": pts["q"], FREQUENCY: pts["f"], damping: pts["zeta"]}
    noise = (float("nan"), float("nan"))
    if scatter is not None:
        missing = [c for c in _SCATTER_COLUMNS if c not in scatter.columns]
        if missing:
            _fail(scatter_name, f"column(s) {', '.join(missing)} missing "
                  f"(found: {', '.join(map(str, scatter.columns))})", "regenerate it with the modal stage")
        noise = (_pooled(scatter, str(assembly), FREQUENCY, floors["frequency"], scatter_name, notes),
                 _pooled(scatter, str(assembly), damping, floors["damping"], scatter_name, notes))
    return ModalData(assembly=str(assembly), run_id=run_id, level=level,
                     q=values["q_in"], f=values[FREQUENCY], zeta=values[damping], damping=damping,
                     rel_noise=noise, notes=tuple(notes), weight=weight, sigma=sigma,
                     q_top=q_top)


def read_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a CSV table, raising `CalibrationInputError` naming the file if it cannot."""
    path = Path(path)
    if not path.is_file():
        _fail(path, "the file does not exist", "run the stage that writes it first")
    try:
        return pd.read_csv(path, keep_default_na=True)
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError) as exc:
        _fail(path, f"cannot be read as CSV ({exc})", "regenerate it")


def read_modal(modal_csv: str | os.PathLike[str], assembly: str, *, scatter_csv: str | os.PathLike[str] | None = None,
               damping: Damping = "zeta_res", floors: Mapping[str, float] | None = None,
               backbone_csv: str | os.PathLike[str] | None = None) -> ModalData:
    """`select_modal` on the files ``modal_properties.csv`` (and ``scatter.csv``, ``backbone.csv``)."""
    scatter = None if scatter_csv is None else read_table(scatter_csv)
    backbone = None if backbone_csv is None else read_backbone(backbone_csv)
    return select_modal(read_table(modal_csv), assembly, damping=damping, scatter=scatter, floors=floors,
                        modal_name=Path(modal_csv), scatter_name=None if scatter_csv is None else Path(scatter_csv),
                        backbone=backbone, backbone_name=None if backbone_csv is None else Path(backbone_csv))


def read_backbone(path: str | os.PathLike[str]) -> pd.DataFrame:
    """backbone.csv (`read_table`, run ids and modes as text)."""
    table = read_table(path)
    for col in ("run_id", "mode", "test"):
        if col in table:
            table[col] = table[col].astype(str)
    return table
