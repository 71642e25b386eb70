"""Snakemake script of rule ``posterior_report``: Fig. 3.8, Table 3.2 and QSMA versus harmonic balance
(`jointcal.report.posterior_stage.run_posterior_report`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.report.posterior_stage import run_posterior_report

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    for line in run_posterior_report(smk.input, smk.params.calibrate, figure_png=smk.output.figure,
                                     table_csv=smk.output.table, markdown_md=smk.output.markdown,
                                     qsma_csv=smk.output.qsma):
        job.log(line)
