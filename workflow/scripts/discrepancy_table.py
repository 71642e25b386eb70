"""Snakemake script of rule ``discrepancy_table``: Table 3.2 with the paper's model and the corrected one.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

from jointcal._stage_job import stage_job
from jointcal._workflow import unit_labels
from jointcal.io import write_bytes_atomic
from jointcal.report.discrepancy import table_3_2_corrected_html

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    names = unit_labels(smk.input.best)  # assembly (and mode: jointcal._workflow)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.best)}
    diag = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.diagnosis)}
    write_bytes_atomic(table_3_2_corrected_html(best, diag).encode(), smk.output.table)
    for a, d in diag.items():
        job.log(f"{a}: {d['effect']} ({d['confidence']}), E {d['metric_before']:.2f} -> {d['metric_after']:.2f}")
