"""Validate one assembly: every run simulated with its model, compared, reduced to E and words.

`validate_runs` is the public entry the discrepancy stage reuses with other models: it
takes one `MinistackModel` per run (a sequence in run order, or a callable run row ->
model), so effect-augmented and per-run (e.g. settling) models are scored with exactly
the same definition of E.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
import pandas as pd

from ..io.contract import LEVEL, excitation_kind
from ..io.testkinds import DEFAULT, run_test_kind, swept_mask
from ..models import MinistackModel
from .error import describe_misfit, envelope_error, repeat_scatter
from .runs import (band_frames, compare_run, draw_transmissibility, full_drive_fraction, measure_pair,
                   reference_column, run_head, time_envelopes)
from .testkinds import validate_test_run
from .._config import config_section

__all__ = ["ValidateSettings", "Validation", "validate_runs"]


@dataclass(frozen=True)
class ValidateSettings:
    """The ``validate:`` config section.

    n_draws : posterior draws behind the predictive band; seed : picks them;
    band : (lo, hi) compared band as fractions of each run's measured resonance;
    floor_db, floor_deg : smallest repeat scatter of magnitude (dB) and phase (deg);
    lead_s : simulated lead-in before the band for the draws (s);
    quantiles : (lo, hi) of the predictive band.
    """

    n_draws: int = 20
    seed: int = 2019
    band: tuple[float, float] = (0.8, 1.2)
    floor_db: float = 0.05
    floor_deg: float = 0.3
    lead_s: float = 0.1
    quantiles: tuple[float, float] = (0.05, 0.95)

    def __post_init__(self) -> None:
        if self.n_draws < 0:
            raise ValueError(f"validate.n_draws must be >= 0, got {self.n_draws!r}")
        if not (len(self.band) == 2 and 0 < self.band[0] < 1 < self.band[1]):
            raise ValueError(f"validate.band must be [lo, hi] with 0 < lo < 1 < hi, got {list(self.band)!r}")
        if not (self.floor_db > 0 and self.floor_deg > 0 and self.lead_s > 0):
            raise ValueError("validate.floor_db, floor_deg and lead_s must be positive, got "
                             f"{self.floor_db!r}, {self.floor_deg!r}, {self.lead_s!r}")
        if not (0 <= self.quantiles[0] < self.quantiles[1] <= 1):
            raise ValueError(f"validate.quantiles must be [lo, hi] within [0, 1], got {list(self.quantiles)!r}")

    @classmethod
    def from_config(cls, section: Mapping[str, Any] | None) -> ValidateSettings:
        """Build from the config's ``validate:`` mapping (missing keys take the defaults)."""
        section = config_section(section, (f.name for f in fields(cls)), "validate")
        for key in ("band", "quantiles"):
            if key in section:
                section[key] = tuple(float(v) for v in section[key])
        return cls(**section)


@dataclass
class Validation:
    """Outcome of `validate_runs`.

    metrics : one row per run (`compare_run` metrics + sim_s, process_s, draws_s times);
    frames : run_id -> `compare_run` frames (+ predictive-band columns when draws were given);
    scale : `repeat_scatter` table; error : `envelope_error` dict (E and its parts);
    words : `describe_misfit` text; traces : run_id -> `time_envelopes` (force- and voltage-driven
    runs: the response envelope in time, measured and simulated).
    """

    metrics: pd.DataFrame
    frames: dict[str, pd.DataFrame]
    scale: pd.DataFrame
    error: dict
    words: str
    traces: dict[str, pd.DataFrame] = field(default_factory=dict)


def _one_run(model: MinistackModel, record: pd.DataFrame, row: dict, draws: Sequence[MinistackModel],
             s: ValidateSettings, envelopes_kw: dict | None, modal_kw: dict | None):
    if not run_test_kind(row).swept:  # a dwell or ring-down: its point and decay (no predictive band)
        frames, metrics = validate_test_run(model, record, row, floor_db=s.floor_db, floor_deg=s.floor_deg)
        return frames, {**metrics, "draws_s": 0.0, "n_draws": 0}, None
    t0 = time.perf_counter()
    try:
        (env_m, meta_m, props_m), (env_s, _, props_s), sim_record = measure_pair(
            model, record, row, envelopes_kw=envelopes_kw, modal_kw=modal_kw, with_record=True)
    except ValueError as exc:  # a record the envelopes cannot process: reported, the other runs go on
        return pd.DataFrame(), {**run_head(row), "n_frames": 0, "note": str(exc)}, None
    t1 = time.perf_counter()
    frames, metrics = compare_run(env_m, props_m, env_s, props_s, band=s.band)
    metrics = {**{k: v for k, v in run_head(row).items() if k not in metrics}, **metrics}  # the manifest's sweep rate
    trace = None
    if reference_column(record) != "base_accel_g" and np.isfinite(metrics.get("f_res_meas_hz", np.nan)):
        trace = time_envelopes(record, sim_record, metrics["f_res_meas_hz"], float(row["sample_rate_hz"]))
    t2 = time.perf_counter()
    if draws and len(frames):
        fd = full_drive_fraction(props_m)
        sel = band_frames(env_m, metrics["f_res_meas_hz"], s.band, full_drive=fd)
        T = draw_transmissibility(draws, record, env_m, meta_m, sel, lead_s=s.lead_s, meta_row=row)
        T_m = ((env_m["resp_re"] + 1j * env_m["resp_im"]) / (env_m["ref_re"] + 1j * env_m["ref_im"])).to_numpy()[sel]
        pos = pd.Series(np.arange(len(frames)), index=np.flatnonzero(band_frames(env_m, metrics["f_res_meas_hz"],
                                                                                 (0.0, np.inf), full_drive=fd)))
        rows = pos.reindex(np.flatnonzero(sel)).to_numpy()
        keep = np.isfinite(rows)
        rows = rows[keep].astype(int)
        mag = 20 * np.log10(np.abs(T[:, keep]))
        ph = frames["phase_meas_deg"].to_numpy()[rows] + np.degrees(np.angle(T[:, keep] / T_m[keep]))
        for name, v in (("mag", mag), ("phase", ph)):
            unit = "db" if name == "mag" else "deg"
            for q in s.quantiles:
                col = np.full(len(frames), np.nan)
                col[rows] = np.quantile(v, q, axis=0)
                frames[f"{name}_q{round(q * 100):02d}_{unit}"] = col
    metrics.update(sim_s=t1 - t0, compare_s=t2 - t1, draws_s=time.perf_counter() - t2, n_draws=len(draws))
    return frames, metrics, trace


def validate_runs(models: Sequence[MinistackModel] | Callable[[dict], MinistackModel],
                  records: Sequence[pd.DataFrame], rows: Sequence[Mapping], *,
                  settings: ValidateSettings = ValidateSettings(),
                  draws: Sequence[MinistackModel] | Callable[[dict], Sequence[MinistackModel]] = (),
                  envelopes_kw: dict | None = None, modal_kw: dict | None = None,
                  executor: Executor | None = None) -> Validation:
    """Simulate, measure and compare every run of one assembly; E and the misfit in words.

    A sweep is compared frame by frame (`compare_run`); a dwell or a ring-down (the row's ``test``) by its
    steady point and its decay (`jointcal.validate.testkinds.validate_test_run`), and metrics.csv then has a
    ``test`` column. The scale of the sweeps' frames is their repeat scatter (`repeat_scatter`, over the
    sweeps alone); a dwell's and a ring-down's are their read-outs' own.

    Parameters
    ----------
    models : sequence of MinistackModel (one per run, in `rows` order) or callable row -> MinistackModel
        The model of each run, driven by that run's measured reference record.
    records : sequence of DataFrame
        The measured records (time_s, the reference channel, response_accel_g; g).
    rows : sequence of mapping
        Their manifest rows (run_id, level_g, direction, f_start_hz, f_stop_hz, sample_rate_hz, test, dwell_hz,
        ...; ``mode_hz``, the frequency the modal stage read the run at).
    settings : ValidateSettings
    draws : sequence of MinistackModel, or callable row -> sequence
        Posterior-draw models for the predictive band (not used by E); empty for none.
    envelopes_kw, modal_kw : dict, optional
        The config's ``envelopes`` and ``modal`` sections (the measurement's own settings).
    executor : concurrent.futures.Executor, optional
        Runs are mapped over it (e.g. a ProcessPoolExecutor sized from snakemake.threads).

    Returns
    -------
    Validation
    """
    rows = [dict(r) for r in rows]
    if len(records) != len(rows):
        raise ValueError(f"validate_runs: {len(records)} records for {len(rows)} manifest rows.")
    per_run = list(models) if not callable(models) else [models(r) for r in rows]
    if len(per_run) != len(rows):
        raise ValueError(f"validate_runs: {len(per_run)} models for {len(rows)} runs; give one model per run.")
    per_draws = [list(draws(r)) if callable(draws) else list(draws) for r in rows]
    args = [(m, rec, r, d, settings, envelopes_kw, modal_kw) for m, rec, r, d in zip(per_run, records, rows, per_draws)]
    results = list(executor.map(_one_run, *zip(*args))) if executor is not None else [_one_run(*a) for a in args]
    frames = {r["run_id"]: fr for r, (fr, _, _) in zip(rows, results)}
    traces = {r["run_id"]: tr for r, (_, _, tr) in zip(rows, results) if tr is not None}
    metrics = pd.DataFrame([mt for _, mt, _ in results])
    swept = metrics
    if "test" in metrics:  # dwells or ring-downs among the runs: every row names its kind; the scale is the sweeps'
        metrics.insert(list(metrics.columns).index("n_frames"), "test", metrics.pop("test").fillna(DEFAULT))
        swept = metrics[swept_mask(metrics["test"])]
    scale = repeat_scatter(frames, swept, floor_db=settings.floor_db, floor_deg=settings.floor_deg)
    error = envelope_error(frames, metrics, scale)
    return Validation(metrics=metrics, frames=frames, scale=scale, error=error, traces=traces,
                      words=describe_misfit(metrics, error, level_unit=LEVEL[excitation_kind(
                          metrics.columns)].split("_", 1)[1]))
