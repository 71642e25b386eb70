"""Snakemake script of rule ``report_summary``: the report's opening summary (HTML), its landing text and
Table 3.2 rendered.

The summary opens on the verdict of the whole run (jointcal.report.verdict) from the validation,
discrepancy and design stages' outputs where the workflow has them.
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal._workflow import unit_labels, unit_of
from jointcal.calibrate import PARAMS, CalibrateSettings, model_words, read_modal
from jointcal.io import write_bytes_atomic
from jointcal.posterior import NAMES, PosteriorSettings, find_modes
from jointcal.posterior.noise import scale_words
from jointcal.report.summary import bound_hits, chain_status, ga_best_point, landing_html, summary_html
from jointcal.report.table_3_2 import table_3_2_html
from jointcal.posterior.identified import identified_at, settled
from jointcal.report.verdict import corrected_holds, identified_html, verdict_html, verdict_items


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
        lines.append(f"Fit of the polished optimum: rms relative residuals {ratio[0]:.1f} (frequency) and {ratio[1]:.1f} "
                     f"(damping) x {scale_words(_sources(arrays))}; chi-square {float(arrays['fit_chi2']):.0f} for "
                     f"{int(arrays['fit_dof'])} degrees of freedom (p = {float(arrays['fit_p']):.1g}).")
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


def main(smk) -> None:
    cal = CalibrateSettings.from_config(smk.params.calibrate)
    post = PosteriorSettings.from_config(smk.params.posterior)
    names = unit_labels(smk.input.best)  # assembly (and mode: jointcal._workflow)
    status, modes, fits, details = {}, {}, {}, {}
    identified = {a: settled(pd.read_csv(p)) for a, p in zip(names, smk.input.identified)}  # as a user is told
    for a, chain in zip(names, smk.input.chain):
        with np.load(chain) as z:
            arrays = {k: z[k] for k in z.files}
        status[a] = chain_status(arrays, tau_factor=post.tau_factor)
        if "sample_mode" in arrays:
            modes[a] = find_modes(arrays["samples"], NAMES, labels=arrays["sample_mode"])
        if "fit_p" in arrays:
            fits[a] = {k: float(arrays[k]) for k in ("fit_chi2", "fit_dof", "fit_p")} | {"noise_source": _sources(arrays)}
        details[a] = _details(arrays, modes.get(a), identified[a])
    ga = {a: ga_best_point(pd.read_csv(p)) for a, p in zip(names, smk.input.history)}
    table = pd.read_csv(smk.input.table)
    best = _json(smk.input.best, names)
    validation = _json(smk.input.get("validation", []), names)
    diagnosis = _json(smk.input.get("diagnosis", []), names)
    design = _json(smk.input.get("design", []), names)
    bounds = {a: cal.resolved(best[a]).full_bounds for a in names}
    corrected = {}
    for a, d in diagnosis.items():  # which joint parameters the runs identify at the corrected model's point
        if corrected_holds(d):
            ca = cal.resolved(best[a])
            unit_modal, unit_scatter = dict(zip(names, smk.input.unit_modal))[a], dict(zip(names, smk.input.unit_scatter))[a]
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
    modal = pd.read_csv(smk.input.modal, dtype={"flags": str})
    runs = pd.read_csv(smk.input.runs[0], dtype={"flags": str}) if len(smk.input.runs) else modal
    page = summary_html(campaign=str(smk.params.campaign), runs=runs, modal=modal, status=status,
                        constraints=details, table_html=table_html, verdict=verdict_html(items), identified=ident)
    write_bytes_atomic(page.encode(), smk.output.summary)
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
    landing = landing_html(runs=runs, modal=modal, status=status, notes=notes, verdict=verdict_html(items, landing=True))
    write_bytes_atomic(landing.encode(), smk.output.landing)
    write_bytes_atomic(table_html.encode(), smk.output.table)
    Path(smk.log[0]).write_text("".join(f"jointcal: {a}: {line}\n" for a, (_, line) in status.items()))


main(snakemake)  # noqa: F821 (provided by Snakemake)
