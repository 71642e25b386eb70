# Stage validate: the calibrated model driven by each run's measured base record, through the
# same envelopes and modal code (jointcal.validate); Fig. 3.11.


rule validate_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
        chain=POSTERIOR / "{assembly}" / "{mode}" / "chain.npz",
        records=assembly_records,
        kernels=ancient(KERNELS),
    output:
        metrics=VALIDATION / "{assembly}" / "{mode}" / "metrics.csv",
        summary=VALIDATION / "{assembly}" / "{mode}" / "summary.json",
        envelopes=directory(VALIDATION / "{assembly}" / "{mode}" / "envelopes"),
    params:
        code=source_hash("validate.py"),
        validate=config.get("validate", {}),
        envelopes=config["envelopes"],
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: pool_threads
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "validate_assembly" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "validate" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/validate.py"


rule validate_figures:
    input:
        metrics=unit_files(VALIDATION / "{assembly}" / "{mode}" / "metrics.csv"),
        summary=unit_files(VALIDATION / "{assembly}" / "{mode}" / "summary.json"),
        envelopes=unit_files(VALIDATION / "{assembly}" / "{mode}" / "envelopes"),
    output:
        figure=report(FIGURES / "fig3_11_validation.png", caption="../report/fig3_11_validation.rst",
                      category="4. Validation"),
    params:
        code=source_hash("validate_figures.py"),
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "validate_figures.tsv"
    log:
        RESULTS / "logs" / "validate_figures.log",
    script:
        "../scripts/validate_figures.py"


rule validate:
    input:
        unit_files(VALIDATION / "{assembly}" / "{mode}" / "summary.json"),
        rules.validate_figures.output,
