"""Snakemake script of rule ``calibrate_assembly``: GA on eq. 3.9 for one assembly.

Writes ga_best.json, ga_history.csv, ga_logbook.csv and model_curves.csv; resumes from
the GA checkpoint in params.checkpoint when it matches; the GA's progress reaches the log
as it runs. A bad input table or setting ends the job with one sentence in the log and on
stderr (`jointcal._stage_job`). (No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

from jointcal._stage_job import stage_job
from jointcal.calibrate import CalibrateSettings, run_calibration

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    settings = CalibrateSettings.from_config(smk.params.calibrate)
    _, notes = run_calibration(smk.input.modal, smk.wildcards.assembly, Path(smk.output.best).parent, settings,
                               checkpoint=smk.params.checkpoint, progress=job.log, backbone_csv=smk.input.backbone)
    for n in notes:
        job.log(n)
