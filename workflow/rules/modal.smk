# Stage modal: resonance, damping and amplitude per run, scatter across repeats (jointcal.measure.modal).

checkpoint modal_properties:  # its table names the (assembly, mode) units of the later stages
    input:
        runs=INGEST / "runs.csv",
        env=expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
        meta=expand(ENVELOPES / "{run_id}.json", run_id=RUN_IDS),
        records=campaign_records,
    output:
        table=MODAL / "modal_properties.csv",
        scatter=MODAL / "scatter.csv",
        backbone=MODAL / "backbone.csv",
        frf=directory(MODAL / "frf"),
    params:
        code=source_hash("modal.py"),
        modal=config["modal"],
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "modal_properties.tsv"
    log:
        RESULTS / "logs" / "modal.log",
    script:
        "../scripts/modal.py"


rule modal_figures:
    input:
        table=MODAL / "modal_properties.csv",
        runs=INGEST / "runs.csv",
        env=expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
        records=campaign_records,
    output:
        envelopes=report(FIGURES / "fig3_5_envelopes.png",
                         caption="../report/fig3_5_envelopes.rst", category="1. Modal properties"),
        amplitude=report(FIGURES / "fig3_6_frequency_damping.png",
                         caption="../report/fig3_6_frequency_damping.rst", category="1. Modal properties"),
        spectrogram=report(FIGURES / "spectrogram_ridge.png",
                           caption="../report/spectrogram_ridge.rst", category="1. Modal properties"),
    params:
        code=source_hash("modal_figures.py"),
        envelopes=config["envelopes"],
    benchmark:
        RESULTS / "benchmarks" / "modal_figures.tsv"
    log:
        RESULTS / "logs" / "modal_figures.log",
    script:
        "../scripts/modal_figures.py"


rule modal:
    input:
        rules.modal_properties.output,
        rules.modal_figures.output,
