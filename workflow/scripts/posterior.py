"""Snakemake script of rule ``posterior_assembly``: emcee around the GA optimum of one assembly
(`jointcal.posterior.unit_stage.run_posterior_unit`).

Writes summary.csv, chain.npz, constraints.txt and predictive.csv; resumes from the chain
checkpoint in params.checkpoint when it matches. Then identified.csv: which parameters and
combinations the data identify, from the draws (jointcal.posterior.identified.write_identified).
Floors applied to the noise scales and a chain stopped by max_steps before tau_factor tau are
warnings (stderr and the log).
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.posterior.unit_stage import run_posterior_unit

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    run_posterior_unit(smk.input.modal, smk.input.scatter, smk.input.backbone, smk.input.best, smk.wildcards.assembly,
                       summary_csv=smk.output.summary, chain_npz=smk.output.chain, identified_csv=smk.output.identified,
                       calibrate=smk.params.calibrate, posterior=smk.params.posterior,
                       checkpoint=smk.params.checkpoint, log=job.log, warn=job.warn)
