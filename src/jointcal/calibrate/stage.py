"""The calibration stage on files: read the modal table, run the GA with checkpoints, write outputs.

Outputs in ``out_dir`` (all written atomically): ``ga_best.json``, ``ga_history.csv``
(generation, objective, Fs, KT, chi, beta, k, zeta_v of every evaluated individual),
``ga_logbook.csv`` (gen, nevals, min, median, max of the population's objective, best so
far, mean mutation sigma) and ``model_curves.csv`` (q_in, f_hz, zeta, model).

The checkpoint (a pickle of the GA state, written every ``checkpoint_every``
generations) lives outside the stage's declared outputs because Snakemake deletes a
job's outputs before rerunning it. It carries a fingerprint of the data and settings
(all but ``generations`` and ``checkpoint_every``); a checkpoint with another
fingerprint is ignored and the run starts afresh.
"""
from __future__ import annotations

import hashlib
import json
import os
import pickle
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

from ..io import write_bytes_atomic, write_csv_atomic, write_json_atomic
from .data import ModalData, read_modal
from .fit import Calibration, calibrate
from .settings import CalibrateSettings

__all__ = ["OUTPUTS", "fingerprint", "run_calibration"]

OUTPUTS = ("ga_best.json", "ga_history.csv", "ga_logbook.csv", "model_curves.csv")


def fingerprint(data: ModalData, s: CalibrateSettings) -> str:
    """SHA-256 of the data and the settings that change the GA's course."""
    ga = {k: v for k, v in asdict(s.ga).items() if k not in ("generations", "checkpoint_every")}
    cfg = dict(model=s.model, viscous=s.viscous, damping=s.damping, eta=s.eta, m=s.m,
               bounds={k: list(map(float, v)) for k, v in s.bounds.items()}, ga=ga)
    h = hashlib.sha256(json.dumps(cfg, sort_keys=True).encode())
    for a in (data.q, data.f, data.zeta):
        h.update(a.tobytes())
    return h.hexdigest()


def run_calibration(modal_csv: str | os.PathLike[str], assembly: str, out_dir: str | os.PathLike[str],
                    settings: CalibrateSettings, *, checkpoint: str | os.PathLike[str] | None = None,
                    progress: Callable[[str], None] | None = None) -> tuple[Calibration, list[str]]:
    """Calibrate one assembly from ``modal_properties.csv`` and write the stage's outputs.

    Parameters
    ----------
    modal_csv : path-like
        The modal stage's ``modal_properties.csv``.
    assembly : str
        Assembly to calibrate.
    out_dir : path-like
        Folder for `OUTPUTS` (created).
    settings : CalibrateSettings
    checkpoint : path-like, optional
        GA checkpoint file: resumed from when it matches, rewritten as the GA runs.
    progress : callable, optional
        Receives one line (generation, best objective, stall count) every
        ``checkpoint_every`` generations, for the stage's log.

    Returns
    -------
    calibration : Calibration
    notes : list of str
        Lines for the log (excluded runs, resume, result).

    Raises
    ------
    jointcal.calibrate.CalibrationInputError
        The modal table breaks its contract (one sentence naming the file).
    """
    data = read_modal(modal_csv, assembly, damping=settings.damping)  # type: ignore[arg-type]
    notes = list(data.notes)
    fp = fingerprint(data, settings)
    resume = None
    ckpt = None if checkpoint is None else Path(checkpoint)
    if ckpt is not None and ckpt.is_file():
        try:
            saved = pickle.loads(ckpt.read_bytes())
        except Exception as exc:  # a damaged checkpoint only costs the time to recompute
            saved = {}
            notes.append(f"{ckpt}: unreadable checkpoint ({type(exc).__name__}); starting afresh")
        if saved.get("fingerprint") == fp:
            resume = saved["ga"]
            notes.append(f"{ckpt}: resuming the GA after generation {resume['generation']}")
        elif saved:
            notes.append(f"{ckpt}: checkpoint made with other data or settings; starting afresh")

    reported: list[int] = []

    def save(state: dict) -> None:
        if ckpt is not None:
            write_bytes_atomic(pickle.dumps({"fingerprint": fp, "ga": state}, protocol=4), ckpt)
        if progress is not None and state["generation"] not in reported:  # (the last one comes twice)
            reported.append(state["generation"])
            progress(f"GA generation {state['generation']}/{settings.ga.generations}: best objective "
                     f"{state['hof'][0].fitness.values[0]:.6g}, generations without improvement: {state['stall']}"
                     + (f"; checkpoint {ckpt}" if ckpt is not None else ""))

    cal = calibrate(data, settings, resume=resume, on_checkpoint=None if ckpt is None and progress is None else save)
    out = Path(out_dir)
    write_json_atomic(cal.best, out / "ga_best.json")
    write_csv_atomic(cal.history, out / "ga_history.csv")
    write_csv_atomic(cal.logbook, out / "ga_logbook.csv")
    write_csv_atomic(cal.curves, out / "model_curves.csv")
    b = cal.best
    notes.append(f"calibrated {assembly!r} on {b['n_runs']} runs ({settings.model}, eta {settings.eta}, "
                 f"{settings.damping}): objective {b['objective']:.6g} (GA alone {b['objective_ga']:.6g}) after "
                 f"{b['generations']} generations ({b['stop_reason']}), {b['n_evaluations']} evaluations")
    return cal, notes
