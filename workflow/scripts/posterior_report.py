"""Snakemake script of rule ``posterior_report``: Fig. 3.8, Table 3.2 and QSMA versus harmonic balance.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal._workflow import unit_labels, unit_of
from jointcal.calibrate import CalibrateSettings, read_modal
from jointcal.io import write_bytes_atomic, write_csv_atomic
from jointcal.report.calibration import amplitude_figure
from jointcal.report.tables import qsma_at_measured, table_3_2, table_3_2_markdown

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, cal = job.smk, CalibrateSettings.from_config(job.smk.params.calibrate)
    names = unit_labels(smk.input.best)  # assembly (and mode: jointcal._workflow)
    best = {a: json.loads(Path(p).read_text()) for a, p in zip(names, smk.input.best)}
    measured, comparison = {}, []
    for a, unit_modal in zip(names, smk.input.modal):
        d = read_modal(unit_modal, unit_of(unit_modal)[0], damping=cal.damping)
        measured[a] = pd.DataFrame({"q_in": d.q, "f_hz": d.f, "zeta": d.zeta})
        comparison.append(qsma_at_measured(best[a], d, a, m=cal.resolved(best[a]).m, viscous=cal.viscous))
    curves, bands, summaries, identified = ({a: pd.read_csv(p) for a, p in zip(names, files)} for files in (
        smk.input.curves, smk.input.predictive, smk.input.summary, smk.input.identified))
    write_bytes_atomic(amplitude_figure(measured, curves, bands, model=cal.model), smk.output.figure)
    table = table_3_2(best, summaries, identified)
    write_csv_atomic(table, smk.output.table)
    write_bytes_atomic(table_3_2_markdown(table).encode(), smk.output.markdown)
    qvh = pd.concat(comparison, ignore_index=True)
    write_csv_atomic(qvh, smk.output.qsma)
    for a, g in qvh.groupby("assembly", sort=False):
        job.log(f"{a}: QSMA frequency above harmonic balance by {g['df_percent'].min():.3f}% to "
                f"{g['df_percent'].max():.3f}% at the measured amplitudes")
