"""The validation stage on files: one (assembly, mode)'s runs simulated with the calibrated model, compared, written.

Outputs (all written atomically): ``metrics.csv`` (one row per run, `validate_runs`; with dwells or ring-downs
a ``test`` column, and their parts of E),
``summary.json`` (E and its parts, the misfit in words, the median read-out errors, the model,
the settings, the wall time) and the ``envelopes/`` folder (each run's measured and simulated
frames, ``<run_id>.csv``, or a dwell's point and a decay's windows, `jointcal.validate.testkinds`; a force- or
voltage-driven swept run's response envelope in time, ``traces/<run_id>.csv``). With dwells or ring-downs the
summary adds E_f, E_zeta and ``per_test`` (E and its parts per test kind).

The GA optimum gives E and the metrics; posterior draws give the predictive band only. A force or
voltage drives the calibrated mode through the campaign's modal constant
(`jointcal.validate.drive.drive_gain`), which the words then state.
"""
from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import excitation_kind, listed_record, read_run, write_csv_atomic, write_json_atomic
from .assembly import ValidateSettings, validate_runs
from .models import models_from_samples, run_models
from .testkinds import as_read
from .drive import drive_gain, dwell_gain

__all__ = ["run_validation"]

_Path = str | os.PathLike[str]


def _drive_words(gain: tuple[complex, complex, float], kind: str, by: str = "the swept-mode fits") -> str:
    """How a force- or voltage-driven model is driven, in words (the modal constant A and its slope)."""
    return (f" How the model is driven: the calibrated mode is driven by its modal force per unit modal mass "
            f"A(w) r(t), the recorded {'force' if kind == 'force' else 'amplifier voltage'} through "
            f"the campaign's modal constant A = {gain[0].real:.4g}{gain[0].imag:+.4g}i "
            f"(in/s^2 per reference unit at {gain[2] / (2 * np.pi):.4g} Hz, sloped "
            f"{abs(gain[1]) * gain[2] / abs(gain[0]):.3g} of itself per unit w/w_c), the median over {by}"
            + (": the shaker's electrical and residual dynamics in one complex gain; its "
                                 "back-EMF damping is in the calibrated mode's." if kind == "voltage" else "."))


def _median(m: pd.DataFrame, col: str) -> float | None:
    """The median of a metrics column over the runs that have it (the sweeps'), None where none has."""
    return float(np.nanmedian(m[col])) if col in m and m[col].notna().any() else None


def run_validation(best_json: _Path, runs_csv: _Path, modal_csv: _Path, chain_npz: _Path, records: Sequence[_Path],
                   assembly: str, config: Mapping, *, metrics_csv: _Path, summary_json: _Path, envelopes_dir: _Path,
                   envelopes_kw: Mapping, modal_kw: Mapping, executor: Executor | None = None, workers: int = 1,
                   log: Callable[[str], None] = lambda line: None,
                   warn: Callable[[str], None] = lambda line: None) -> dict:
    """Validate one (assembly, mode) and write the stage's outputs.

    Parameters
    ----------
    best_json, runs_csv, modal_csv, chain_npz : path-like
        ``ga_best.json``, the ingest stage's ``runs.csv``, this unit's ``modal_properties.csv``
        and ``chain.npz`` (the posterior's draws).
    records : sequence of path-like
        The campaign's run files (each run's found by its manifest path, `jointcal.io.listed_record`).
    assembly : str
        Named in the words and the summary.
    config : mapping
        The config's ``validate`` section (`ValidateSettings.from_config`), copied to the summary.
    metrics_csv, summary_json, envelopes_dir : path-like
        Where the outputs go.
    envelopes_kw, modal_kw : mapping
        The config's ``envelopes`` and ``modal`` sections (the measurement's own settings).
    executor : concurrent.futures.Executor, optional
        The runs are mapped over it; `workers` is its size, for the log.
    log, warn : callable, optional
        Receive the lines for the log: the misfit in words, then a warning per run not
        validated, then the runs, draws and times.

    Returns
    -------
    dict
        The summary written to `summary_json`.

    Raises
    ------
    ValueError
        A setting or input table that breaks its contract (one sentence).
    """
    t0 = time.perf_counter()
    s = ValidateSettings.from_config(config)
    best = json.loads(Path(best_json).read_text())
    runs = pd.read_csv(runs_csv, dtype={"flags": str})
    modal_table = pd.read_csv(modal_csv)  # this (assembly, mode)'s rows
    modal = modal_table.set_index("run_id")
    rows = as_read(runs[runs["run_id"].isin(modal.index)].to_dict("records"), modal_table)
    recs = [read_run(listed_record(str(r["file"]), list(records)), r) for r in rows]
    kind = excitation_kind(recs[0])
    gain = drive_gain(modal_table) if kind != "base" else None
    by = "the dwells' fits" if gain is not None and gain == dwell_gain(modal_table) else "the swept-mode fits"
    if gain is not None:  # a force or voltage drives the mode through the campaign's modal constant
        rows = [{**r, "drive_gain": gain} for r in rows]
    models, f_ref = run_models(best, modal["f_res_hz"].to_dict(), [r["run_id"] for r in rows])
    with np.load(chain_npz) as z:
        samples = z["samples"]
    draws = models_from_samples(samples, float(best["m"]), s.n_draws, np.random.default_rng(s.seed),
                                viscous=str(best.get("viscous", "dashpot")), f_ref_hz=f_ref)
    v = validate_runs(models, recs, rows, settings=s, draws=draws, envelopes_kw=dict(envelopes_kw),
                      modal_kw=dict(modal_kw), executor=executor)
    out = Path(envelopes_dir)
    for rid, fr in v.frames.items():
        if len(fr):
            write_csv_atomic(fr, out / f"{rid}.csv")
    out.mkdir(parents=True, exist_ok=True)
    for rid, tr in v.traces.items():  # force- and voltage-driven runs: the response envelope in time
        write_csv_atomic(tr, out / "traces" / f"{rid}.csv")
    m = v.metrics
    write_csv_atomic(m, metrics_csv)
    words = v.words + (_drive_words(gain, kind, by) if gain is not None else "")
    summary = {**{k: v.error[k] for k in ("E", "E_mag", "E_phase", "n_runs", "per_level", "scale")},
               **{k: v.error[k] for k in ("E_f", "E_zeta", "per_test") if k in v.error},  # dwells, ring-downs
               "words": words, "assembly": assembly, "n_draws": len(draws),
               **{f"median_{c}": _median(m, c) for c in ("peak_ratio", "f_res_rel_err", "zeta_rel_err")},
               "model": {k: best[k] for k in ("Fs", "KT", "chi", "beta", "k", "zeta_v", "m", "viscous")},
               "settings": dict(config), "wall_s": time.perf_counter() - t0}
    write_json_atomic(summary, summary_json)
    log(f"{assembly}: {words}")
    for r in m.itertuples():
        if r.n_frames == 0:
            warn(f"{r.run_id}: not validated: {r.note}")
    t = m[m["n_frames"] > 0]
    log(f"{len(m)} runs, {len(draws)} posterior draws, {workers} workers, {summary['wall_s']:.1f} s wall; "
        f"per run: optimum simulation + processing {t['sim_s'].mean():.2f} s, posterior draws "
        f"{t['draws_s'].mean():.2f} s")
    return summary
