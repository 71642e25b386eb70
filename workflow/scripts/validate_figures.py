"""Snakemake script of rule ``validate_figures``: Fig. 3.11 from the validation tables
(`jointcal.report.validation_stage.run_validate_figures`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.validation_stage import run_validate_figures

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    for line in run_validate_figures(smk.input.metrics, smk.input.summary, smk.input.envelopes,
                                     figure_png=smk.output.figure):
        job.log(line)
