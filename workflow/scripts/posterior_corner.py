"""Snakemake script of rule ``posterior_corner``: corner plot of one assembly's posterior draws, stamped with
its convergence, the GA best, the polished optimum, the prior bounds and its modes; and the run-generated
part of its caption.

Axes: log10 of the scale parameters and noise scales, chi linear (jointcal.report._corner_axes).
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal._stage_job import stage_job
from jointcal.calibrate import PARAMS, CalibrateSettings
from jointcal.io import write_bytes_atomic
from jointcal.posterior import PosteriorSettings
from jointcal.report._corner_axes import corner_coordinates
from jointcal.report.corner import corner_figure
from jointcal.report.summary import chain_status, ga_best_point, rst_escape

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    best = json.loads(Path(smk.input.best).read_text())
    cal = CalibrateSettings.from_config(smk.params.calibrate).resolved(best)
    with np.load(smk.input.chain) as z:
        arrays = {k: z[k] for k in z.files}
    samples, names = arrays["samples"], [str(n) for n in arrays["sample_names"]]
    points = {"GA best": ga_best_point(pd.read_csv(smk.input.history)),
              "polished optimum": {p: best[p] for p in PARAMS}}
    x, labels, points, bounds = corner_coordinates(samples, names, points, cal.full_bounds)
    ok, line = chain_status(arrays, tau_factor=PosteriorSettings.from_config(smk.params.posterior).tau_factor)
    write_bytes_atomic(corner_figure(x, labels, title=f"posterior of {smk.wildcards.assembly}", points=points,
                                     bounds=bounds, modes=arrays.get("sample_mode"), stamp=(line.split(";")[0], ok)),
                       smk.output.corner)
    text = [f"**This run: {rst_escape(line)}.**"]
    text += [rst_escape(s) for s in Path(smk.input.constraints).read_text().splitlines()[1:] if s.strip()]
    write_bytes_atomic(("\n\n".join(text) + "\n").encode(), smk.output.caption)
    job.log(f"corner plot of {len(samples)} posterior draws; {line}")
