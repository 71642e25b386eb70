"""Snakemake script of rule ``validate_figures``: Fig. 3.11 from the validation tables.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal._workflow import unit_labels
from jointcal.io import write_bytes_atomic
from jointcal.report.validation import validation_figure

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    names = unit_labels(smk.input.summary)  # assembly (and mode: jointcal._workflow)
    metrics = {a: pd.read_csv(p) for a, p in zip(names, smk.input.metrics)}
    errors = {a: json.loads(Path(p).read_text())["E"] for a, p in zip(names, smk.input.summary)}
    frames = {a: {p.stem: pd.read_csv(p) for p in sorted(Path(d).glob("*.csv"))}
              for a, d in zip(names, smk.input.envelopes)}
    traces = {a: {p.stem: pd.read_csv(p) for p in sorted((Path(d) / "traces").glob("*.csv"))}
              for a, d in zip(names, smk.input.envelopes)}
    write_bytes_atomic(validation_figure(frames, metrics, errors, traces=traces), smk.output.figure)
    for a, e in errors.items():
        job.log(f"{a}: E = {e:.2f}")
