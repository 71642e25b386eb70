"""Snakemake script of rule ``calibration_figures``: GA exploration matrix (Figs. 3.9/3.10) and convergence.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

import pandas as pd

from jointcal.io import write_bytes_atomic
from jointcal.report.calibration import convergence_figure, exploration_figure


def main(smk) -> None:
    name = smk.wildcards.assembly
    history = pd.read_csv(smk.input.history)
    write_bytes_atomic(exploration_figure(history, title=name), smk.output.exploration)
    write_bytes_atomic(convergence_figure({name: pd.read_csv(smk.input.logbook)}), smk.output.convergence)
    Path(smk.log[0]).write_text(f"jointcal: GA figures of {name!r} from {len(history)} evaluations\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
