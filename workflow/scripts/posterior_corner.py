"""Snakemake script of rule ``posterior_corner``: corner plot of one assembly's posterior draws, stamped with
its convergence, the GA best, the polished optimum, the prior bounds and its modes; and the run-generated
part of its caption (`jointcal.report.posterior_stage.run_posterior_corner`).

Axes: log10 of the scale parameters and noise scales, chi linear (jointcal.report._corner_axes).
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.posterior_stage import run_posterior_corner

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    job.log(run_posterior_corner(smk.input.chain, smk.input.constraints, smk.input.best, smk.input.history,
                                 smk.wildcards.assembly, calibrate=smk.params.calibrate,
                                 posterior=smk.params.posterior, corner_png=smk.output.corner,
                                 caption_rst=smk.output.caption))
