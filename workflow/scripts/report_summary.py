"""Snakemake script of rule ``report_summary``: the report's opening summary (HTML), its landing text and
Table 3.2 rendered (`jointcal.report.stage.run_summary`).

The summary opens on the verdict of the whole run (jointcal.report.verdict) from the validation,
discrepancy and design stages' outputs where the workflow has them.
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.stage import run_summary

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    for line in run_summary(smk.input, smk.params.calibrate, smk.params.posterior, smk.params.campaign,
                            summary_html_out=smk.output.summary, landing_out=smk.output.landing,
                            table_out=smk.output.table):
        job.log(line)
