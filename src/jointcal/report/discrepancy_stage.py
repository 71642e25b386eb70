"""The discrepancy's table on files (rule ``discrepancy_table``): Table 3.2 with the paper's model and the
corrected one over every unit, named by `jointcal._campaign_index.unit_labels`.

One module per report rule, so that each rule's code hash (`jointcal._workflow.stage_hash`) holds the
code it runs and no more.
"""
from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path

from .._campaign_index import unit_labels
from ..io import write_bytes_atomic
from .discrepancy import table_3_2_corrected_html

__all__ = ["run_discrepancy_table"]

_Path = str | os.PathLike[str]


def run_discrepancy_table(best_files: Sequence[_Path], diagnosis_files: Sequence[_Path], *,
                          table_html: _Path) -> list[str]:
    """Table 3.2 with the paper's model and the corrected one (HTML), one unit per file.

    Parameters
    ----------
    best_files, diagnosis_files : sequence of paths
        Each unit's ``ga_best.json`` and ``diagnosis.json``, in one order.
    table_html : path
        Where the table goes.

    Returns
    -------
    list of str
        One line per unit for the log: the effect named and E before and after.
    """
    names = unit_labels(best_files)  # assembly (and mode: jointcal._campaign_index)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, best_files)}
    diag = {a: json.loads(Path(p).read_text()) for a, p in zip(names, diagnosis_files)}
    write_bytes_atomic(table_3_2_corrected_html(best, diag).encode(), table_html)
    return [f"{a}: {d['effect']} ({d['confidence']}), E {d['metric_before']:.2f} -> {d['metric_after']:.2f}"
            for a, d in diag.items()]
