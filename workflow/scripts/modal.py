"""Snakemake script of rule ``modal_properties``: modal_properties.csv, scatter.csv, backbone.csv, frf/
(`jointcal.measure.stage.run_modal`).

Every run gets a row per mode its band holds; a run with problems gets flags and a one-sentence
warning in the log and on stderr, never a silent drop. (No ``from __future__``: Snakemake prepends a
preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.measure.stage import run_modal

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    run_modal(smk.input.runs, smk.input.env, smk.input.records, smk.params.modal, table_csv=smk.output.table,
              scatter_csv=smk.output.scatter, backbone_csv=smk.output.backbone, frf_dir=smk.output.frf,
              warn=job.warn, log=job.log)
