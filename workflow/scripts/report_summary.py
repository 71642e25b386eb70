"""Snakemake script of rule ``report_summary``: the report's opening summary (HTML) and Table 3.2 rendered.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.calibrate import CalibrateSettings, model_words
from jointcal.io import write_bytes_atomic
from jointcal.posterior import NAMES, PosteriorSettings, find_modes
from jointcal.report.summary import bound_hits, chain_status, ga_best_point, landing_html, summary_html, table_3_2_html


def main(smk) -> None:
    cal = CalibrateSettings.from_config(smk.params.calibrate)
    post = PosteriorSettings.from_config(smk.params.posterior)
    names = list(smk.params.assemblies)
    status, modes, constraints = {}, {}, {}
    for a, chain, text in zip(names, smk.input.chain, smk.input.constraints):
        with np.load(chain) as z:
            arrays = {k: z[k] for k in z.files}
        status[a] = chain_status(arrays, tau_factor=post.tau_factor)
        if "sample_mode" in arrays:
            modes[a] = find_modes(arrays["samples"], NAMES, labels=arrays["sample_mode"])
        constraints[a] = Path(text).read_text()
    ga = {a: ga_best_point(pd.read_csv(p)) for a, p in zip(names, smk.input.history)}
    table = pd.read_csv(smk.input.table)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.best)}
    bounds = {a: cal.resolved(best[a]).full_bounds for a in names}
    table_html = table_3_2_html(table, ga, modes, bounds, {a: model_words(best[a]) for a in names})
    modal = pd.read_csv(smk.input.modal, dtype={"flags": str})
    runs = pd.read_csv(smk.input.runs[0], dtype={"flags": str}) if len(smk.input.runs) else modal
    page = summary_html(campaign=str(smk.params.campaign), runs=runs, modal=modal, status=status,
                        constraints=constraints, table_html=table_html)
    write_bytes_atomic(page.encode(), smk.output.summary)
    notes = {}
    for a, g in table.groupby("assembly", sort=False):
        n = []
        if a in modes and modes[a]["mode"].max() > 0:
            n.append(f"MULTIMODAL ({int(modes[a]['mode'].max()) + 1} modes)")
        hits = bound_hits(dict(zip(g["param"], g["ga_optimum"])), bounds[a])
        if hits:
            n.append("optimum at a bound: " + ", ".join(f"{p} ({side})" for p, side in hits.items()))
        notes[a] = n
    write_bytes_atomic(landing_html(runs=runs, modal=modal, status=status, notes=notes).encode(), smk.output.landing)
    write_bytes_atomic(table_html.encode(), smk.output.table)
    Path(smk.log[0]).write_text("".join(f"jointcal: {a}: {line}\n" for a, (_, line) in status.items()))


main(snakemake)  # noqa: F821 (provided by Snakemake)
