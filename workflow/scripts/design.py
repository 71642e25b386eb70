"""Snakemake script of rule ``design_assembly``: one assembly's next test and its figure
(`jointcal.design.stage.run_design_unit`).

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

from jointcal._stage_job import stage_job
from jointcal.design.stage import run_design_unit

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, asm = job.smk, job.smk.wildcards.assembly
    line = run_design_unit(smk.input.runs, smk.input.modal, smk.input.scatter, smk.input.best, smk.input.chain,
                           smk.input.identified, asm, Path(smk.output.json).parent, figure_png=smk.output.figure,
                           design=smk.params.design, calibrate=smk.params.calibrate,
                           posterior=smk.params.posterior, modal=smk.params.modal)
    job.log(f"{asm}: {line} ({job.elapsed:.1f} s)")
