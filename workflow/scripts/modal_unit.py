"""Snakemake script of rule ``modal_unit``: one (assembly, mode)'s rows of modal_properties.csv, scatter.csv and
backbone.csv (its runs' points of that mode), the tables the later stages of that unit read
(`jointcal.measure.stage.run_modal_unit`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.measure.stage import run_modal_unit

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    job.log(run_modal_unit(smk.input.table, smk.input.scatter, smk.input.backbone, smk.wildcards.assembly,
                           smk.wildcards.mode, unit_table_csv=smk.output.table, unit_scatter_csv=smk.output.scatter,
                           unit_backbone_csv=smk.output.backbone))
