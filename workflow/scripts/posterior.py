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
    log_file = open(log, "w", buffering=1)  # line-buffered: GA/chain progress can be read while the job runs

    def progress(line: str) -> None:
        log_file.write(f"jointcal: {line}\n")

    try:
        cal = CalibrateSettings.from_config(smk.params.calibrate)
        post = PosteriorSettings.from_config(smk.params.posterior)
        res, notes = run_posterior(smk.input.modal, smk.input.scatter, smk.input.best, smk.wildcards.assembly,
                                   Path(smk.output.summary).parent, cal, post, checkpoint=smk.params.checkpoint,
                                   progress=progress)
    except (CalibrationInputError, ValueError) as exc:
        progress(str(exc))
        sys.exit(f"jointcal: {exc}")
    for n in notes:
        if "floor" in n or "NOT converged" in n:
            print(f"jointcal: warning: {n}", file=sys.stderr)
    for n in notes:
        progress(n)


main(snakemake)  # noqa: F821 (provided by Snakemake)
