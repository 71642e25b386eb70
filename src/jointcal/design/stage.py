"""The design stage on files: one assembly's next test, from its posterior and its runs.

Reads the ingest stage's ``runs.csv`` (band, rate, levels, directions), the modal stage's
``modal_properties.csv`` and ``scatter.csv``, the calibration's ``ga_best.json`` (model
kind, mass, bounds), the posterior's ``chain.npz`` (draws in physical units) and
``identified.csv``; writes (atomically) ``next_test.json``, ``next_test.csv`` (every
candidate, ranked) and ``next_test.md``.

The prediction runs through the Ministack's base-driven steady-state model. For a
force- or voltage-driven campaign (calibration model kind ``modal``) the amplitude a
level in lbf or V would reach depends on the modal mass and, for a voltage, on the
shaker's own dynamics, which the calibration does not hold: the stage says so in words,
with the amplitude a test would have to reach, and recommends no level.
"""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..calibrate.data import read_modal, read_table
from ..calibrate.settings import CalibrateSettings
from ..io import write_bytes_atomic, write_csv_atomic, write_json_atomic
from ..posterior.settings import PosteriorSettings
from ..report.design import design_figure
from .candidates import candidates
from .evaluate import REPORTED, evaluate
from .recommend import next_test_markdown, rank, recommendation
from .settings import DesignSettings

__all__ = ["OUTPUTS", "targets_of", "words_now", "run_design", "run_design_unit"]

OUTPUTS = ("next_test.json", "next_test.csv", "next_test.md")


def targets_of(identified: pd.DataFrame) -> list[str]:
    """What the next test should identify: Fs and the KT/k split where the data leave them free, else any
    parameter they leave free, else nothing."""
    free = set(identified.loc[~identified["identified"].astype(bool), "quantity"])
    first = [n for n in ("Fs", "KT/k") if n in free]
    return first or [n for n in ("Fs", "KT", "chi", "beta", "k", "zeta_v") if n in free]


def _g(v: float) -> str:
    return f"{v:.3g}"


def words_now(identified: pd.DataFrame, q_max: float) -> str:
    """One paragraph: what the runs in hand identify and what they leave to the bounds."""
    t = identified.set_index("quantity")
    fixed = [n for n in t.index if t.loc[n, "identified"] and t.loc[n, "kind"] != "curve"]
    free = [n for n in t.index if not t.loc[n, "identified"]]
    text = (f"The runs in hand (largest joint amplitude {_g(q_max)} in) identify {', '.join(fixed) or 'nothing'} "
            f"({int(t['fixed_directions'].iloc[0])} of the 6 directions of the parameter space); they leave "
            f"{', '.join(free) or 'nothing'} to the bounds.")
    if "phi_max" in t.index and not t.loc["phi_max", "identified"]:
        pm = t.loc["phi_max"]
        text += (f" Macroslip (phi_max, eq. 3.7) starts between {_g(pm['q05'])} and {_g(pm['q95'])} in (90% of the "
                 "posterior): only an amplitude past it shows Fs and the KT/k split.")
    return text


def _not_applicable(best: dict, identified: pd.DataFrame, assembly: str, q_max: float) -> tuple[dict, str]:
    exc = best.get("excitation", "force")
    unit = {"force": "lbf", "voltage": "V"}.get(exc, "its own unit")
    pm = identified.set_index("quantity").loc["phi_max"]
    reason = (f"This campaign is {exc}-driven (calibration model kind {best.get('model_kind')!r}, levels in {unit}). "
              "The design's steady-state model is the base-driven Ministack's: the joint amplitude a force or "
              "voltage level reaches depends on the modal mass at the drive point"
              + (" (unknown here: the results are per unit modal mass)" if best.get("per_unit_modal_mass", True)
                 else "")
              + (" and on the shaker's electrical and mechanical dynamics, which are in the calibrated mode"
                 if exc == "voltage" else "")
              + f", so no level in {unit} is recommended.")
    need = "What would identify Fs and the KT/k split: a response amplitude q_in past macroslip. " + _past_macroslip(
        pm, q_max, exc)
    rec = {"assembly": assembly, "applicable": False, "recommended": None, "reason": reason, "what_would_identify": need,
           "phi_max_interval_in": [float(pm["q05"]), float(pm["q95"])], "largest_amplitude_in": q_max,
           "targets": targets_of(identified), "predicted_width_ratio": {}}
    md = f"# Next test: assembly {assembly}\n\n**No level recommended.** {reason}\n\n{need}\n"
    return rec, md


def _past_macroslip(pm: pd.Series, q_max: float, exc: str) -> str:
    """Where macroslip lies (phi_max, eq. 3.7: the identified table's row `pm`) and how to reach it, in words: a
    target amplitude only where the data place phi_max, never an end the search bounds set."""
    step = f"Raise the {exc} level in steps and read q_in from the modal stage"
    if not bool(pm["identified"]):
        return (f"The data do not place phi_max (eq. 3.7): its 90% range, {_g(pm['q05'])} to {_g(pm['q95'])} in, is "
                f"what the search bounds leave; the largest amplitude measured is {_g(q_max)} in. {step} until the "
                "frequency and damping leave the power law of the lower levels: there macroslip begins.")
    if q_max >= pm["q95"]:
        return (f"The posterior puts phi_max between {_g(pm['q05'])} and {_g(pm['q95'])} in (90%), below the largest "
                f"amplitude measured ({_g(q_max)} in): the runs already pass it, and what they leave free is not for "
                "want of amplitude (more levels near that range, or repeated runs, narrow it).")
    return (f"The posterior puts phi_max between {_g(pm['q05'])} and {_g(pm['q95'])} in (90%); the largest amplitude "
            f"measured is {_g(q_max)} in. {step} until it exceeds {_g(pm['q95'])} in, or until the frequency and "
            "damping leave the power law of the lower levels.")


def run_design(runs_csv: str | os.PathLike[str], modal_csv: str | os.PathLike[str],
               scatter_csv: str | os.PathLike[str], ga_best_json: str | os.PathLike[str],
               chain_npz: str | os.PathLike[str], identified_csv: str | os.PathLike[str], assembly: str,
               out_dir: str | os.PathLike[str], cal: CalibrateSettings, settings: DesignSettings, *,
               eta_max: float, floors: dict[str, float] | None = None) -> tuple[dict[str, Any], pd.DataFrame]:
    """Design one assembly's next test and write `OUTPUTS` in `out_dir`.

    Parameters
    ----------
    runs_csv, modal_csv, scatter_csv, ga_best_json, chain_npz, identified_csv : path-like
        The stages' outputs (see the module notes).
    assembly : str
    out_dir : path-like
    cal : CalibrateSettings
        The config's calibration settings (resolved with ga_best.json).
    settings : DesignSettings
    eta_max : float
        ``modal.eta_max``.
    floors : dict, optional
        ``posterior.rel_std_floor`` (the noise floors the posterior used).

    Returns
    -------
    recommendation : dict
        next_test.json's content.
    ranked : DataFrame
        next_test.csv's content (empty when the design does not apply).
    """
    best = json.loads(Path(ga_best_json).read_text())
    cal = cal.resolved(best)
    identified = read_table(identified_csv)
    data = read_modal(modal_csv, assembly, scatter_csv=scatter_csv, damping=cal.damping, floors=floors)  # type: ignore[arg-type]
    q_max = float(np.max(data.q))
    out = Path(out_dir)
    if cal.model_kind != "ministack" or best.get("excitation", "base") != "base":
        rec, md = _not_applicable(best, identified, assembly, q_max)
        ranked = pd.DataFrame(columns=["rank", "level_g", "direction", "sweep_rate_hz_per_s"])
    else:
        runs = read_table(runs_csv)
        runs = runs[runs["assembly"].astype(str) == assembly]
        with np.load(chain_npz) as z:
            samples, names = np.asarray(z["samples"], dtype=float), [str(n) for n in z["sample_names"]]
        targets = targets_of(identified)
        cands = candidates(runs, settings)
        table, per_q = evaluate(cands, samples, names, cal.space, identified, data.q, data.f, data.zeta, settings,
                                m=cal.m, rel_scatter_f=data.rel_noise[0], eta_max=eta_max, targets=targets,
                                model=cal.model, viscous=cal.viscous)
        ranked = rank(table, targets, settings.confidence, settings.directions, min(settings.draws, len(samples)))
        rec = recommendation(ranked, per_q, targets=targets, confidence=settings.confidence, reported=REPORTED,
                             assembly=assembly, max_level_g=settings.max_level_g)
        md = next_test_markdown(rec, ranked, words_now=words_now(identified, q_max))
    write_json_atomic(rec, out / "next_test.json")
    write_csv_atomic(ranked, out / "next_test.csv")
    write_bytes_atomic(md.encode(), out / "next_test.md")
    return rec, ranked


def run_design_unit(runs_csv: str | os.PathLike[str], modal_csv: str | os.PathLike[str],
                    scatter_csv: str | os.PathLike[str], ga_best_json: str | os.PathLike[str],
                    chain_npz: str | os.PathLike[str], identified_csv: str | os.PathLike[str], assembly: str,
                    out_dir: str | os.PathLike[str], *, figure_png: str | os.PathLike[str],
                    design: Mapping[str, Any], calibrate: Mapping[str, Any], posterior: Mapping[str, Any],
                    modal: Mapping[str, Any]) -> str:
    """`run_design` from the config's sections, and the next test's figure (`jointcal.report.design`).

    Parameters
    ----------
    runs_csv, modal_csv, scatter_csv, ga_best_json, chain_npz, identified_csv : path-like
        The stages' outputs (see the module notes).
    assembly : str
    out_dir : path-like
        Folder of `OUTPUTS`.
    figure_png : path-like
        Where the figure goes.
    design, calibrate, posterior, modal : mapping
        The config's sections (``modal.eta_max``, ``posterior.rel_std_floor``).

    Returns
    -------
    str
        The line for the log: the recommended test and its predicted width ratios, or why none is.
    """
    cal = CalibrateSettings.from_config(calibrate)
    post = PosteriorSettings.from_config(posterior)
    rec, ranked = run_design(runs_csv, modal_csv, scatter_csv, ga_best_json, chain_npz, identified_csv, assembly,
                             out_dir, cal, DesignSettings.from_config(design),
                             eta_max=float(modal.get("eta_max", 0.5)), floors=dict(post.rel_std_floor))
    data = read_modal(modal_csv, assembly, damping=cal.resolved(json.loads(Path(ga_best_json).read_text())).damping)
    measured = pd.DataFrame({"level": data.level, "f_hz": data.f, "zeta": data.zeta, "q_in": data.q})
    write_bytes_atomic(design_figure(rec, ranked, measured, pd.read_csv(identified_csv)), figure_png)
    r = rec["recommended"]
    return (f"recommended {r['level_g']:g} g {r['direction']} at {r['sweep_rate_hz_per_s']:g} Hz/s; predicted width "
            "ratios " + ", ".join(f"{k} {v:.3g}" for k, v in rec["predicted_width_ratio"].items())
            if r else f"no level recommended: {rec['reason']}")
