"""Snakemake script of rule ``validate_assembly``: simulate every run of one assembly with the
calibrated model driven by its measured record; metrics.csv, summary.json, envelopes/
(`jointcal.validate.stage.run_validation`).

Runs are spread over a process pool of snakemake.threads workers. The misfit in words goes
to the log and summary.json. (No ``from __future__``: Snakemake prepends a preamble.)
"""
from jointcal._stage_job import stage_job
from jointcal.validate.stage import run_validation

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    with job.pool() as ex:
        run_validation(smk.input.best, smk.input.runs, smk.input.modal, smk.input.chain, list(smk.input.records),
                       smk.wildcards.assembly, smk.params.validate, metrics_csv=smk.output.metrics,
                       summary_json=smk.output.summary, envelopes_dir=smk.output.envelopes,
                       envelopes_kw=smk.params.envelopes, modal_kw=smk.params.modal, executor=ex,
                       workers=job.workers(), log=job.log, warn=job.warn)
