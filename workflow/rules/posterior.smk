# Stage posterior: emcee around each GA optimum (jointcal.posterior); corner plots, Fig. 3.8, Table 3.2.
# Chain checkpoints live in <results>/checkpoints/ (not declared outputs: an interrupted
# chain resumes from its last chunk).

rule posterior_assembly:
    input:
        modal=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        scatter=MODAL / "{assembly}" / "{mode}" / "scatter.csv",
        backbone=MODAL / "{assembly}" / "{mode}" / "backbone.csv",
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
    output:
        summary=POSTERIOR / "{assembly}" / "{mode}" / "summary.csv",
        chain=POSTERIOR / "{assembly}" / "{mode}" / "chain.npz",
        constraints=POSTERIOR / "{assembly}" / "{mode}" / "constraints.txt",
        predictive=POSTERIOR / "{assembly}" / "{mode}" / "predictive.csv",
        identified=POSTERIOR / "{assembly}" / "{mode}" / "identified.csv",
    params:
        code=source_hash("posterior.py"),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
        checkpoint=lambda wc: str(RESULTS / "checkpoints" / "posterior" / f"{wc.assembly}_{wc.mode}.npz"),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "posterior_assembly" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "posterior" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/posterior.py"


rule posterior_corner:
    input:
        chain=POSTERIOR / "{assembly}" / "{mode}" / "chain.npz",
        constraints=POSTERIOR / "{assembly}" / "{mode}" / "constraints.txt",
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "{mode}" / "ga_history.csv",
    output:
        corner=report(FIGURES / "corner_{assembly}_{mode}.png", caption="../report/corner.rst",
                      category="3. Posterior", subcategory="{assembly} {mode}"),
        caption=REPORT / "corner_{assembly}_{mode}.rst",
    params:
        code=source_hash("posterior_corner.py"),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "posterior_corner" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "posterior_corner" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/posterior_corner.py"


rule posterior_report:
    input:
        modal=unit_files(MODAL / "{assembly}" / "{mode}" / "modal_properties.csv"),
        best=unit_files(CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json"),
        curves=unit_files(CALIBRATION / "{assembly}" / "{mode}" / "model_curves.csv"),
        summary=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "summary.csv"),
        predictive=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "predictive.csv"),
        identified=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "identified.csv"),
    output:
        figure=report(FIGURES / "fig3_8_amplitude_fit.png", caption="../report/fig3_8_amplitude_fit.rst",
                      category="3. Posterior"),
        table=POSTERIOR / "table_3_2.csv",
        markdown=POSTERIOR / "table_3_2.md",
        qsma=POSTERIOR / "qsma_vs_harmonic_balance.csv",
    params:
        code=source_hash("posterior_report.py"),
        calibrate=config.get("calibrate", {}),
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "posterior_report.tsv"
    log:
        RESULTS / "logs" / "posterior_report.log",
    script:
        "../scripts/posterior_report.py"


rule posterior:
    input:
        unit_files(POSTERIOR / "{assembly}" / "{mode}" / "summary.csv"),
        unit_files(FIGURES / "corner_{assembly}_{mode}.png"),
        rules.posterior_report.output,
