"""Snakemake script of rule ``calibrate_assembly``: GA on eq. 3.9 for one assembly.

Writes ga_best.json, ga_history.csv, ga_logbook.csv and model_curves.csv; resumes from
the GA checkpoint in params.checkpoint when it matches. A bad input table or setting
ends the job with one sentence in the log and on stderr. (No ``from __future__``:
Snakemake prepends a preamble to scripts.)
"""
import sys
from pathlib import Path

from jointcal.calibrate import CalibrateSettings, CalibrationInputError, run_calibration


def main(smk) -> None:
    log = Path(smk.log[0])
    log_file = open(log, "w", buffering=1)  # line-buffered: GA/chain progress can be read while the job runs

    def progress(line: str) -> None:
        log_file.write(f"jointcal: {line}\n")

    try:
        settings = CalibrateSettings.from_config(smk.params.calibrate)
        _, notes = run_calibration(smk.input.modal, smk.wildcards.assembly, Path(smk.output.best).parent, settings,
                                   checkpoint=smk.params.checkpoint, progress=progress,
                                   backbone_csv=smk.input.backbone)
    except (CalibrationInputError, ValueError) as exc:
        progress(str(exc))
        sys.exit(f"jointcal: {exc}")
    for n in notes:
        progress(n)


main(snakemake)  # noqa: F821 (provided by Snakemake)
