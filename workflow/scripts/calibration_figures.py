"""Snakemake script of rule ``calibration_figures``: GA exploration matrix (Figs. 3.9/3.10), convergence,
and the run-generated part of their captions.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.io import write_bytes_atomic
from jointcal.report.calibration import convergence_figure, exploration_caption, exploration_figure
from jointcal.report.summary import ga_best_point

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, name = job.smk, job.smk.wildcards.assembly
    history = pd.read_csv(smk.input.history)
    best = json.loads(Path(smk.input.best).read_text())
    bounds = CalibrateSettings.from_config(smk.params.calibrate).resolved(best).full_bounds
    ga = ga_best_point(history)
    polished = {p: best[p] for p in PARAMS} | {"objective": best["objective"]}
    write_bytes_atomic(exploration_figure(history, title=name, ga_best=ga, polished=polished, bounds=bounds),
                       smk.output.exploration)
    write_bytes_atomic(convergence_figure({name: pd.read_csv(smk.input.logbook)}), smk.output.convergence)
    write_bytes_atomic(exploration_caption(history, best, ga, polished, bounds).encode(), smk.output.caption)
    job.log(f"GA figures of {name!r} from {len(history)} evaluations")
