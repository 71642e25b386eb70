"""Snakemake script of rule ``discrepancy_table``: Table 3.2 with the paper's model and the corrected one
(`jointcal.report.discrepancy_stage.run_discrepancy_table`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.discrepancy_stage import run_discrepancy_table

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    for line in run_discrepancy_table(smk.input.best, smk.input.diagnosis, table_html=smk.output.table):
        job.log(line)
