"""Snakemake script of rule ``modal_figures``: Figs. 3.5 and 3.6 and a spectrogram. (No ``from __future__``.)

Fig. 3.5 shows the sweeps' envelopes (a dwell or ring-down run has none); the spectrogram is of the strongest
sweep, or of the strongest run (a 2 s window) in a campaign without sweeps.
"""
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal.io import level_column, listed_record, read_run, test_kind
from jointcal.measure.envelopes import window_length
from jointcal.report.modal import plot_envelopes, plot_frequency_damping, plot_spectrogram

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    table = pd.read_csv(smk.input.table, dtype={"flags": str})
    runs = pd.read_csv(smk.input.runs, dtype={"flags": str}).set_index("run_id", drop=False)
    envs = {Path(p).stem: pd.read_csv(p) for p in smk.input.env}
    sweeps = runs[[test_kind(r) == "sweep" for r in runs.to_dict("records")]]
    plot_envelopes(table[table["run_id"].isin(sweeps["run_id"])], envs, smk.output.envelopes)
    plot_frequency_damping(table, smk.output.amplitude)
    level = level_column(runs.columns) or "level_g"
    rid = (sweeps if len(sweeps) else runs).sort_values([level, "sequence"]).iloc[-1]["run_id"]  # the strongest run
    row = runs.loc[rid]
    if len(sweeps):
        lo = min(row["f_start_hz"], row["f_stop_hz"])
        n = window_length(row["sample_rate_hz"], row["sweep_rate_hz_per_s"], lo, **{
            k: v for k, v in smk.params.envelopes.items() if k == "zeta_min"})
    else:
        n = int(round(2.0 * row["sample_rate_hz"]))
    record = read_run(listed_record(row["file"], list(smk.input.records)), row)  # whole path: basenames may repeat
    plot_spectrogram(record, envs[rid], row["sample_rate_hz"], n, rid, smk.output.spectrogram)
    job.log(f"figures written; spectrogram of {rid}")
