"""Snakemake script of rule ``discrepancy_table``: Table 3.2 with the paper's model and the corrected one.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

from jointcal._workflow import unit_labels
from jointcal.io import write_bytes_atomic
from jointcal.report.discrepancy import table_3_2_corrected_html


def main(smk) -> None:
    names = unit_labels(smk.input.best)  # assembly (and mode: jointcal._workflow)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.best)}
    diag = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.diagnosis)}
    write_bytes_atomic(table_3_2_corrected_html(best, diag).encode(), smk.output.table)
    Path(smk.log[0]).write_text("".join(f"jointcal: {a}: {d['effect']} ({d['confidence']}), E "
                                        f"{d['metric_before']:.2f} -> {d['metric_after']:.2f}\n" for a, d in diag.items()))


main(snakemake)  # noqa: F821 (provided by Snakemake)
