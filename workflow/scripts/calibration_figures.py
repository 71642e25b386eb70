"""Snakemake script of rule ``calibration_figures``: GA exploration matrix (Figs. 3.9/3.10), convergence,
and the run-generated part of their captions (`jointcal.report.calibration_stage.run_calibration_figures`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.calibration_stage import run_calibration_figures

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    job.log(run_calibration_figures(smk.input.history, smk.input.logbook, smk.input.best, smk.wildcards.assembly,
                                    smk.params.calibrate, exploration_png=smk.output.exploration,
                                    convergence_png=smk.output.convergence, caption_rst=smk.output.caption))
