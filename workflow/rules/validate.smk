# Stage validate: the calibrated model driven by each run's measured base record, through the
# same envelopes and modal code (jointcal.validate); Fig. 3.11.


rule validate_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "modal_properties.csv",
        best=CALIBRATION / "{assembly}" / "ga_best.json",
        chain=POSTERIOR / "{assembly}" / "chain.npz",
        records=assembly_records,
        kernels=ancient(KERNELS),
    output:
        metrics=VALIDATION / "{assembly}" / "metrics.csv",
        summary=VALIDATION / "{assembly}" / "summary.json",
        envelopes=directory(VALIDATION / "{assembly}" / "envelopes"),
    params:
        code=source_hash("validate.py"),
        validate=config.get("validate", {}),
        envelopes=config["envelopes"],
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: pool_threads
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "validate_assembly" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "validate" / "{assembly}.log",
    script:
        "../scripts/validate.py"


rule validate_figures:
    input:
        metrics=expand(VALIDATION / "{assembly}" / "metrics.csv", assembly=ASSEMBLIES),
        summary=expand(VALIDATION / "{assembly}" / "summary.json", assembly=ASSEMBLIES),
        envelopes=expand(VALIDATION / "{assembly}" / "envelopes", assembly=ASSEMBLIES),
    output:
        figure=report(FIGURES / "fig3_11_validation.png", caption="../report/fig3_11_validation.rst",
                      category="4. Validation"),
    params:
        code=source_hash("validate_figures.py"),
        assemblies=ASSEMBLIES,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "validate_figures.tsv"
    log:
        RESULTS / "logs" / "validate_figures.log",
    script:
        "../scripts/validate_figures.py"


rule validate:
    input:
        expand(VALIDATION / "{assembly}" / "summary.json", assembly=ASSEMBLIES),
        rules.validate_figures.output,
