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

from dataclasses import replace

from ..io import write_bytes_atomic, write_csv_atomic, write_json_atomic
from .data import ModalData, read_backbone, read_table, select_modal
from .fit import Calibration, calibrate
from .kind import data_bounds, excitation_of_table, kind_of
from .settings import CalibrateSettings

__all__ = ["OUTPUTS", "fingerprint", "resolve", "run_calibration"]

OUTPUTS = ("ga_best.json", "ga_history.csv", "ga_logbook.csv", "model_curves.csv")


def fingerprint(data: ModalData, s: CalibrateSettings) -> str:
    """SHA-256 of the data and the settings that change the GA's course."""
    ga = {k: v for k, v in asdict(s.ga).items() if k not in ("generations", "checkpoint_every")}
    cfg = dict(model=s.model, viscous=s.viscous, damping=s.damping, eta=s.eta, m=s.m, kind=s.model_kind,
               bounds=s.full_bounds, ga=ga)
    h = hashlib.sha256(json.dumps(cfg, sort_keys=True).encode())
    for a in (data.q, data.f, data.zeta) + (() if data.weight is None else (data.w,)):
        h.update(a.tobytes())
    return h.hexdigest()


def resolve(settings: CalibrateSettings, modal, assembly: str, *, modal_name: object = "modal_properties.csv",
            backbone=None, backbone_name: object = "backbone.csv") -> tuple[CalibrateSettings, ModalData, str]:
    """The settings made concrete for one assembly's data: model kind, mass and all six bounds.

    Parameters
    ----------
    settings : CalibrateSettings
        From the config (``model_kind`` may be 'auto', ``bounds`` partial).
    modal : DataFrame
        The modal stage's table.
    assembly : str
    backbone : DataFrame, optional
        backbone.csv: ring-down and dwell runs then give their points (`jointcal.calibrate.select_modal`).

    Returns
    -------
    settings : CalibrateSettings (model_kind 'ministack' or 'modal', all six bounds)
    data : ModalData
    excitation : str ('base', 'force' or 'voltage')
    """
    excitation = excitation_of_table(modal)
    kind = kind_of(settings.model_kind, excitation)
    data = select_modal(modal, assembly, damping=settings.damping, modal_name=modal_name,  # type: ignore[arg-type]
                        backbone=backbone, backbone_name=backbone_name)
    s = replace(settings, model_kind=kind, bounds=dict(settings.bounds))
    if kind == "modal":
        s = replace(s, bounds={**data_bounds(data.q, data.f, data.zeta, s.m), **dict(settings.bounds)})
    else:
        s = replace(s, bounds=s.full_bounds)
    return s, data, excitation


def run_calibration(modal_csv: str | os.PathLike[str], assembly: str, out_dir: str | os.PathLike[str],
                    settings: CalibrateSettings, *, checkpoint: str | os.PathLike[str] | None = None,
                    progress: Callable[[str], None] | None = None,
                    backbone_csv: str | os.PathLike[str] | None = None) -> tuple[Calibration, list[str]]:
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
    backbone_csv : path-like, optional
        The unit's ``backbone.csv``: a ring-down gives its windows, a level's dwells their phase resonance,
        each read-out weighted once (`jointcal.calibrate._readouts`).

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
    backbone = None if backbone_csv is None else read_backbone(backbone_csv)
    settings, data, excitation = resolve(settings, read_table(modal_csv), assembly, modal_name=Path(modal_csv),
                                         backbone=backbone, backbone_name=backbone_csv)
    notes = list(data.notes)
    notes.append(f"model kind {settings.model_kind} ({excitation}-driven runs), m = {settings.m:.6g} lbf s^2/in"
                 + (" (per unit modal mass)" if settings.model_kind == "modal" and settings.modal_mass is None else "")
                 + "; bounds " + ", ".join(f"{k} [{a:.3g}, {b:.3g}]" for k, (a, b) in settings.full_bounds.items()))
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
    cal.best.update(model_kind=settings.model_kind, excitation=excitation, bounds=settings.full_bounds,
                    per_unit_modal_mass=settings.model_kind == "modal" and settings.modal_mass is None)
    out = Path(out_dir)
    write_json_atomic(cal.best, out / "ga_best.json")
    write_csv_atomic(cal.history, out / "ga_history.csv")
    write_csv_atomic(cal.logbook, out / "ga_logbook.csv")
    write_csv_atomic(cal.curves, out / "model_curves.csv")
    b = cal.best
    points = "" if data.weight is None else f" ({b['n_points']} points, {b['n_readouts']:g} read-outs)"
    notes.append(f"calibrated {assembly!r} on {b['n_runs']} runs{points} ({settings.model}, eta {settings.eta}, "
                 f"{settings.damping}): objective {b['objective']:.6g} (GA alone {b['objective_ga']:.6g}) after "
                 f"{b['generations']} generations ({b['stop_reason']}), {b['n_evaluations']} evaluations")
    return cal, notes
