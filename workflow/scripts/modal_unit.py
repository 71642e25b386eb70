"""Snakemake script of rule ``modal_unit``: one (assembly, mode)'s rows of modal_properties.csv, scatter.csv and
backbone.csv (its runs' points of that mode), the tables the later stages of that unit read.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import pandas as pd

from jointcal._stage_job import stage_job
from jointcal._workflow import unit_table
from jointcal.io import write_csv_atomic

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    asm, mode = smk.wildcards.assembly, smk.wildcards.mode
    table = pd.read_csv(smk.input.table, dtype={"assembly": str, "mode": str, "flags": str})
    scatter = pd.read_csv(smk.input.scatter, dtype={"assembly": str, "mode": str})
    rows = unit_table(table, asm, mode)
    write_csv_atomic(rows, smk.output.table)
    keep = scatter["assembly"] == asm
    if "mode" in scatter.columns:  # (a table made before modes were tracked holds one per assembly)
        keep &= scatter["mode"] == mode
    write_csv_atomic(scatter[keep], smk.output.scatter)
    backbone = pd.read_csv(smk.input.backbone, dtype={"run_id": str, "mode": str, "test": str})
    write_csv_atomic(backbone[backbone["run_id"].isin(rows["run_id"].astype(str)) & (backbone["mode"] == mode)],
                     smk.output.backbone)
    job.log(f"{asm} {mode}: {len(rows)} runs ({', '.join(rows['run_id'])})")
