"""Snakemake script of rule ``posterior_assembly``: emcee around the GA optimum of one assembly.

Writes summary.csv, chain.npz, constraints.txt and predictive.csv; resumes from the chain
checkpoint in params.checkpoint when it matches. Then identified.csv: which parameters and
combinations the data identify, from the draws (jointcal.posterior.identified.write_identified).
Floors applied to the noise scales and a chain stopped by max_steps before tau_factor tau are
warnings (stderr and the log).
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

from jointcal._stage_job import stage_job
from jointcal.calibrate import CalibrateSettings
from jointcal.posterior import PosteriorSettings, run_posterior
from jointcal.posterior.identified import write_identified

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, asm = job.smk, job.smk.wildcards.assembly
    cal = CalibrateSettings.from_config(smk.params.calibrate)
    post = PosteriorSettings.from_config(smk.params.posterior)
    res, notes = run_posterior(smk.input.modal, smk.input.scatter, smk.input.best, asm, Path(smk.output.summary).parent,
                               cal, post, checkpoint=smk.params.checkpoint, progress=job.log,
                               backbone_csv=smk.input.backbone)
    notes.append(write_identified(smk.input.modal, smk.input.best, smk.output.chain, asm, cal, post,
                                  smk.output.identified, backbone_csv=smk.input.backbone))
    for n in notes:
        (job.warn if "floor" in n or "NOT converged" in n else job.log)(n)
