"""The report's opening summary on files: the verdict page, its landing text and Table 3.2 rendered.

`run_summary` reads the outputs of every stage the workflow has (validation, discrepancy and
design where present), opens the page on the verdict of the whole run (`jointcal.report.verdict`),
and writes ``summary.html``, ``landing.html`` and ``table_3_2.html`` (atomically).
"""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from .._campaign_index import unit_labels, unit_of
from ..calibrate import PARAMS, CalibrateSettings, model_words, read_modal
from ..io import write_bytes_atomic
from ..posterior import NAMES, PosteriorSettings, find_modes
from ..posterior.identified import identified_at, settled
from ..posterior.noise import scale_words
from .summary import bound_hits, chain_status, ga_best_point, landing_html, p_value, summary_html
from .table_3_2 import table_3_2_html
from .verdict import corrected_holds, identified_html, verdict_html, verdict_items

__all__ = ["run_summary"]


def _json(files, names):
    return {a: json.loads(Path(p).read_text()) for a, p in zip(names, files)} if files else {}


def _sources(arrays: dict) -> tuple:
    """Where the chi-square's noise scales came from (chain.npz's noise_source; older chains: the repeats)."""
    return tuple(str(v) for v in arrays["noise_source"]) if "noise_source" in arrays else ("repeats", "repeats")


def _details(arrays: dict, modes: pd.DataFrame | None, identified: pd.DataFrame) -> str:
    """The posterior's fit and modes in words, without values of parameters the data leave to the bounds."""
    lines = []
    if "fit_p" in arrays:
        ratio = np.asarray(arrays["fit_ratio"], dtype=float)
        lines.append(f"Fit of the polished optimum: rms relative residuals {ratio[0]:.1f} (frequency) and "
                     f"{ratio[1]:.1f} (damping) x {scale_words(_sources(arrays))}; chi-square "
                     f"{float(arrays['fit_chi2']):.0f} for {int(arrays['fit_dof'])} degrees of freedom "
                     f"(p = {p_value(float(arrays['fit_p']))}).")
    if modes is not None and len(modes) and modes["mode"].max() > 0:
        fixed = [p for p in identified.loc[identified["identified"] & (identified["kind"] == "parameter"), "quantity"]]
        parts = []
        for k, g in modes.groupby("mode"):
            g = g.set_index("param")
            loc = ", ".join(f"{p} {g.loc[p, 'median']:.3g}" for p in fixed if p in g.index)
            parts.append(f"mode {k + 1} ({100 * g['weight'].iloc[0]:.0f}% of the draws)" + (f": {loc}" if loc else ""))
        lines.append(f"The posterior has {int(modes['mode'].max()) + 1} separated modes (identified parameters only): "
                     + "; ".join(parts) + ".")
    return "\n".join(lines)


def run_summary(inputs: Mapping, calibrate: Mapping, posterior: Mapping, campaign: str | os.PathLike[str], *,
                summary_html_out: str | os.PathLike[str], landing_out: str | os.PathLike[str],
                table_out: str | os.PathLike[str]) -> list[str]:
    """Write the report's summary page, its landing text and Table 3.2 (HTML) from the stages' outputs.

    Parameters
    ----------
    inputs : mapping
        The files, by the names of rule ``report_summary``'s inputs: ``modal`` (modal_properties.csv),
        ``table`` (table_3_2.csv) and ``runs`` (runs.csv, a list of none or one); one per unit, in one
        order: ``unit_modal``, ``unit_scatter``, ``history``, ``best``, ``chain``, ``identified``; and
        where the workflow has those stages ``validation``, ``diagnosis`` and ``design``.
    calibrate, posterior : mapping
        The config's sections.
    campaign : path-like
        The campaign folder, named on the page.
    summary_html_out, landing_out, table_out : path-like
        Where ``summary.html``, ``landing.html`` and ``table_3_2.html`` go.

    Returns
    -------
    list of str
        One line per unit for the log: its chain's convergence.
    """
    cal = CalibrateSettings.from_config(calibrate)
    post = PosteriorSettings.from_config(posterior)
    names = unit_labels(inputs["best"])  # assembly (and mode: jointcal._workflow)
    status, modes, fits, details = {}, {}, {}, {}
    identified = {a: settled(pd.read_csv(p)) for a, p in zip(names, inputs["identified"])}  # as a user is told
    for a, chain in zip(names, inputs["chain"]):
        with np.load(chain) as z:
            arrays = {k: z[k] for k in z.files}
        status[a] = chain_status(arrays, tau_factor=post.tau_factor)
        if "sample_mode" in arrays:
            modes[a] = find_modes(arrays["samples"], NAMES, labels=arrays["sample_mode"])
        if "fit_p" in arrays:
            fits[a] = ({k: float(arrays[k]) for k in ("fit_chi2", "fit_dof", "fit_p")}
                       | {"noise_source": _sources(arrays)})
        details[a] = _details(arrays, modes.get(a), identified[a])
    ga = {a: ga_best_point(pd.read_csv(p)) for a, p in zip(names, inputs["history"])}
    table = pd.read_csv(inputs["table"])
    best = _json(inputs["best"], names)
    validation = _json(inputs.get("validation", []), names)
    diagnosis = _json(inputs.get("diagnosis", []), names)
    design = _json(inputs.get("design", []), names)
    bounds = {a: cal.resolved(best[a]).full_bounds for a in names}
    corrected = {}
    for a, d in diagnosis.items():  # which joint parameters the runs identify at the corrected model's point
        if corrected_holds(d):
            ca = cal.resolved(best[a])
            unit_modal = dict(zip(names, inputs["unit_modal"]))[a]
            unit_scatter = dict(zip(names, inputs["unit_scatter"]))[a]
            data = read_modal(unit_modal, unit_of(unit_modal)[0], scatter_csv=unit_scatter, damping=ca.damping,
                              floors=dict(post.rel_std_floor))
            theta = [d["recalibrated"]["joint_parameters"][p]["value"] for p in PARAMS]
            corrected[a] = identified_at(theta, data.rel_noise, data.q, ca.space, m=ca.m, model=ca.model,
                                         viscous=ca.viscous, ratio=post.constrained_ratio)
    items = {a: verdict_items(best=best[a], identified=identified[a], validation=validation.get(a), fit=fits.get(a),
                              diagnosis=diagnosis.get(a), next_test=design.get(a), corrected=corrected.get(a))
             for a in names}
    table_html = table_3_2_html(table, ga, modes, bounds, {a: model_words(best[a]) for a in names}, identified)
    ident = "\n".join(identified_html(identified[a], title=f"What the data identify: {a} (the paper's model)")
                      for a in names)
    modal = pd.read_csv(inputs["modal"], dtype={"flags": str})
    runs = pd.read_csv(inputs["runs"][0], dtype={"flags": str}) if len(inputs.get("runs", [])) else modal
    page = summary_html(campaign=str(campaign), runs=runs, modal=modal, status=status,
                        constraints=details, table_html=table_html, verdict=verdict_html(items), identified=ident)
    write_bytes_atomic(page.encode(), summary_html_out)
    notes = {}
    for a, g in table.groupby("assembly", sort=False):
        n = []
        if a in modes and modes[a]["mode"].max() > 0:
            n.append(f"MULTIMODAL ({int(modes[a]['mode'].max()) + 1} modes)")
        fixed = set(identified[a].loc[identified[a]["identified"], "quantity"])
        hits = {p: side for p, side in bound_hits(dict(zip(g["param"], g["ga_optimum"])), bounds[a]).items()
                if p in fixed}
        if hits:
            n.append("optimum at a bound: " + ", ".join(f"{p} ({side})" for p, side in hits.items()))
        notes[a] = n
    landing = landing_html(runs=runs, modal=modal, status=status, notes=notes,
                           verdict=verdict_html(items, landing=True))
    write_bytes_atomic(landing.encode(), landing_out)
    write_bytes_atomic(table_html.encode(), table_out)
    return [f"{a}: {line}" for a, (_, line) in status.items()]
