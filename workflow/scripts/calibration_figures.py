"""Snakemake script of rule ``calibration_figures``: GA exploration matrix (Figs. 3.9/3.10), convergence,
and the run-generated part of their captions.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import pandas as pd

from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.io import write_bytes_atomic
from jointcal.report.calibration import convergence_figure, exploration_figure
from jointcal.report.summary import bound_hits, fmt, ga_best_point, rst_escape


def main(smk) -> None:
    name = smk.wildcards.assembly
    history = pd.read_csv(smk.input.history)
    best = json.loads(Path(smk.input.best).read_text())
    bounds = CalibrateSettings.from_config(smk.params.calibrate).resolved(best).full_bounds
    ga = ga_best_point(history)
    polished = {p: best[p] for p in PARAMS} | {"objective": best["objective"]}
    write_bytes_atomic(exploration_figure(history, title=name, ga_best=ga, polished=polished, bounds=bounds),
                       smk.output.exploration)
    write_bytes_atomic(convergence_figure({name: pd.read_csv(smk.input.logbook)}), smk.output.convergence)
    lines = [f"**This run** ({len(history)} evaluations, {best['generations']} generations, stopped by "
             f"{rst_escape(str(best['stop_reason']))}): GA best objective {fmt(ga['objective'])} at "
             + ", ".join(f"{rst_escape(p)} {fmt(ga[p])}" for p in PARAMS)
             + f"; polished optimum objective {fmt(best['objective'])} at "
             + ", ".join(f"{rst_escape(p)} {fmt(best[p])}" for p in PARAMS) + "."]
    for label, point in (("GA best", ga), ("polished optimum", polished)):
        hits = bound_hits(point, bounds)
        if hits:
            lines.append(f"**At a search bound** ({label}): "
                         + ", ".join(f"{rst_escape(p)} at its {side} bound {fmt(bounds[p][0 if side == 'lower' else 1])}"
                                     for p, side in hits.items()) + ".")
    if best["q_max_in"] >= best["phi_max_in"]:
        lines.append(f"The polished optimum puts macroslip (phi\\_max {fmt(best['phi_max_in'])} in) inside the "
                     f"measured amplitudes (up to {fmt(best['q_max_in'])} in).")
    write_bytes_atomic(("\n\n".join(lines) + "\n").encode(), smk.output.caption)
    Path(smk.log[0]).write_text(f"jointcal: GA figures of {name!r} from {len(history)} evaluations\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
