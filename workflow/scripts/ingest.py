"""Snakemake script of rule ``ingest``: validate the campaign, write runs.csv.

On a contract violation the one-sentence message goes to the log and to stderr, after
the warnings, and the job exits non-zero with no runs.csv (`jointcal._stage_job`).
(No ``from __future__`` import: Snakemake prepends a preamble to scripts, after which
such an import is a SyntaxError.)
"""
from pathlib import Path

from jointcal._stage_job import stage_job
from jointcal.io import ingest_campaign, write_csv_atomic

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    campaign = Path(job.smk.input.manifest).parent
    runs = ingest_campaign(campaign, on_data_problem=job.smk.params.ingest["on_data_problem"])
    write_csv_atomic(runs, job.smk.output.runs)
    job.log(f"ingested {len(runs)} runs ({int((runs['flags'] != '').sum())} flagged) from {campaign}")
