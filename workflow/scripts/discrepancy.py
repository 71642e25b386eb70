"""Snakemake script of rule ``discrepancy_assembly``: diagnose one (assembly, mode)
(`jointcal.discrepancy.stage.run_discrepancy`).

Writes diagnosis.json, diagnosis.md, residuals.csv, metrics_after.csv and the two figures; the
revalidation runs on a process pool of snakemake.threads workers. (No ``from __future__``:
Snakemake prepends a preamble to scripts.)
"""
from jointcal._stage_job import stage_job
from jointcal.discrepancy.stage import run_discrepancy

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, asm = job.smk, job.smk.wildcards.assembly
    config = {k: getattr(smk.params, k) for k in ("discrepancy", "calibrate", "validate", "envelopes", "modal")}
    out = {k: getattr(smk.output, k) for k in ("diagnosis", "markdown", "residuals", "metrics_after",
                                                "residual_figure", "before_after_figure")}
    with job.pool() as ex:
        d = run_discrepancy(asm, runs_csv=smk.input.runs, modal_csv=smk.input.modal, envelope_files=smk.input.env,
                            record_files=smk.input.records, best_json=smk.input.best,
                            history_csv=smk.input.history, validation_json=smk.input.validation,
                            out=out, config=config, executor=ex, log=job.log, backbone_csv=smk.input.backbone)
    job.log(f"{asm}: {d['effect']} ({d['confidence']}); E {d['metric_before']:.2f} -> {d['metric_after']:.2f}; "
            f"{d['seconds']:.0f} s")
