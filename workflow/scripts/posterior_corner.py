"""Snakemake script of rule ``posterior_corner``: corner plot of one assembly's posterior draws.

Axes in the sampling space (log10 of the scale parameters and noise scales, chi linear).
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

import numpy as np

from jointcal.calibrate import LOG_SCALED
from jointcal.io import write_bytes_atomic
from jointcal.report.calibration import corner_figure


def main(smk) -> None:
    with np.load(smk.input.chain) as z:
        samples, names = z["samples"], [str(n) for n in z["sample_names"]]
    log = [LOG_SCALED.get(n, True) for n in names]
    x = np.where(log, np.log10(np.abs(samples)), samples)
    labels = [f"log10 {n}" if lg else n for n, lg in zip(names, log)]
    write_bytes_atomic(corner_figure(x, labels, title=smk.wildcards.assembly), smk.output.corner)
    Path(smk.log[0]).write_text(f"jointcal: corner plot of {len(samples)} posterior draws\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
