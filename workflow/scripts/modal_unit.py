"""Snakemake script of rule ``modal_unit``: one (assembly, mode)'s rows of modal_properties.csv and scatter.csv,
the tables the later stages of that unit read.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

import pandas as pd

from jointcal._workflow import unit_table
from jointcal.io import write_csv_atomic


def main(smk) -> None:
    asm, mode = smk.wildcards.assembly, smk.wildcards.mode
    table = pd.read_csv(smk.input.table, dtype={"assembly": str, "mode": str, "flags": str})
    scatter = pd.read_csv(smk.input.scatter, dtype={"assembly": str, "mode": str})
    rows = unit_table(table, asm, mode)
    write_csv_atomic(rows, smk.output.table)
    keep = scatter["assembly"] == asm
    if "mode" in scatter.columns:  # (a table made before modes were tracked holds one per assembly)
        keep &= scatter["mode"] == mode
    write_csv_atomic(scatter[keep], smk.output.scatter)
    Path(smk.log[0]).write_text(f"jointcal: {asm} {mode}: {len(rows)} runs ({', '.join(rows['run_id'])})\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
