"""Snakemake script of rule ``envelopes_runs``: every run's envelopes and their metadata
(`jointcal.measure.envelopes_stage.run_envelopes`).

The runs are spread over a process pool of snakemake.threads workers. A run that cannot be
processed (too short, no drive found) gets an empty envelope table and its one-sentence
reason in the metadata and the log, so the other runs go on and the modal stage flags it.
(No ``from __future__``: Snakemake prepends a preamble.)
"""
from jointcal._stage_job import stage_job
from jointcal.measure.envelopes_stage import run_envelopes

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    run_envelopes(smk.input.runs, smk.input.records, smk.params.envelopes, smk.output.env, smk.output.meta,
                  mapper=job.map, log=job.log, warn=job.warn)
