"""Snakemake script of rule ``modal_figures``: Figs. 3.5 and 3.6 and a spectrogram
(`jointcal.report.modal_stage.run_modal_figures`). (No ``from __future__``.)

Fig. 3.5 shows the sweeps' envelopes (a dwell or ring-down run has none); the spectrogram is of the strongest
sweep, or of the strongest run (a 2 s window) in a campaign without sweeps.
"""
from jointcal._stage_job import stage_job
from jointcal.report.modal_stage import run_modal_figures

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk = job.smk
    job.log(run_modal_figures(smk.input.table, smk.input.runs, smk.input.env, smk.input.records, smk.params.envelopes,
                              envelopes_png=smk.output.envelopes, amplitude_png=smk.output.amplitude,
                              spectrogram_png=smk.output.spectrogram))
