"""Snakemake script of rule ``posterior_assembly``: emcee around the GA optimum of one assembly.

Writes summary.csv, chain.npz, constraints.txt and predictive.csv; resumes from the chain
checkpoint in params.checkpoint when it matches. Floors applied to the noise scales and
a chain stopped by max_steps before 50 tau are reported on stderr and in the log.
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import sys
from pathlib import Path

from jointcal.calibrate import CalibrateSettings, CalibrationInputError
from jointcal.posterior import PosteriorSettings, run_posterior


def main(smk) -> None:
    log = Path(smk.log[0])
    try:
        cal = CalibrateSettings.from_config(smk.params.calibrate)
        post = PosteriorSettings.from_config(smk.params.posterior)
        res, notes = run_posterior(smk.input.modal, smk.input.scatter, smk.input.best, smk.wildcards.assembly,
                                   Path(smk.output.summary).parent, cal, post, checkpoint=smk.params.checkpoint)
    except (CalibrationInputError, ValueError) as exc:
        log.write_text(f"jointcal: {exc}\n")
        sys.exit(f"jointcal: {exc}")
    for n in notes:
        if "floor" in n or "NOT converged" in n:
            print(f"jointcal: warning: {n}", file=sys.stderr)
    log.write_text("".join(f"jointcal: {n}\n" for n in notes))


main(snakemake)  # noqa: F821 (provided by Snakemake)
