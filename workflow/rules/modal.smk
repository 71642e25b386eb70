# Stage modal: resonance, damping and amplitude per run, scatter across repeats (jointcal.measure.modal).

rule modal_properties:
    input:
        runs=RESULTS / "ingest" / "runs.csv",
        env=expand(RESULTS / "envelopes" / "{run_id}.csv", run_id=RUN_IDS),
        meta=expand(RESULTS / "envelopes" / "{run_id}.json", run_id=RUN_IDS),
        records=campaign_records,
    output:
        table=RESULTS / "modal" / "modal_properties.csv",
        scatter=RESULTS / "modal" / "scatter.csv",
        frf=directory(RESULTS / "modal" / "frf"),
    params:
        code=source_hash("modal.py"),
        modal=config["modal"],
    benchmark:
        RESULTS / "benchmarks" / "modal_properties.tsv"
    log:
        RESULTS / "logs" / "modal.log",
    script:
        "../scripts/modal.py"


rule modal_figures:
    input:
        table=RESULTS / "modal" / "modal_properties.csv",
        runs=RESULTS / "ingest" / "runs.csv",
        env=expand(RESULTS / "envelopes" / "{run_id}.csv", run_id=RUN_IDS),
        records=campaign_records,
    output:
        envelopes=report(RESULTS / "figures" / "fig3_5_envelopes.png",
                         caption="../report/fig3_5_envelopes.rst", category="1. Modal properties"),
        amplitude=report(RESULTS / "figures" / "fig3_6_frequency_damping.png",
                         caption="../report/fig3_6_frequency_damping.rst", category="1. Modal properties"),
        spectrogram=report(RESULTS / "figures" / "spectrogram_ridge.png",
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
