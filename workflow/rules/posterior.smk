# Stage posterior: emcee around each GA optimum (jointcal.posterior); corner plots, Fig. 3.8, Table 3.2.
# Chain checkpoints live in <results>/checkpoints/ (not declared outputs: an interrupted
# chain resumes from its last chunk).

rule posterior_assembly:
    input:
        modal=MODAL / "modal_properties.csv",
        scatter=MODAL / "scatter.csv",
        best=CALIBRATION / "{assembly}" / "ga_best.json",
    output:
        summary=POSTERIOR / "{assembly}" / "summary.csv",
        chain=POSTERIOR / "{assembly}" / "chain.npz",
        constraints=POSTERIOR / "{assembly}" / "constraints.txt",
        predictive=POSTERIOR / "{assembly}" / "predictive.csv",
        identified=POSTERIOR / "{assembly}" / "identified.csv",
    params:
        code=source_hash("posterior.py"),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
        checkpoint=lambda wc: str(RESULTS / "checkpoints" / "posterior" / f"{wc.assembly}.npz"),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: 1
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "posterior_assembly" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "posterior" / "{assembly}.log",
    script:
        "../scripts/posterior.py"


rule posterior_corner:
    input:
        chain=POSTERIOR / "{assembly}" / "chain.npz",
        constraints=POSTERIOR / "{assembly}" / "constraints.txt",
        best=CALIBRATION / "{assembly}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "ga_history.csv",
    output:
        corner=report(FIGURES / "corner_{assembly}.png", caption="../report/corner.rst",
                      category="3. Posterior", subcategory="{assembly}"),
        caption=REPORT / "corner_{assembly}.rst",
    params:
        code=source_hash("posterior_corner.py"),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "posterior_corner" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "posterior_corner" / "{assembly}.log",
    script:
        "../scripts/posterior_corner.py"


rule posterior_report:
    input:
        modal=MODAL / "modal_properties.csv",
        best=expand(CALIBRATION / "{assembly}" / "ga_best.json", assembly=ASSEMBLIES),
        curves=expand(CALIBRATION / "{assembly}" / "model_curves.csv", assembly=ASSEMBLIES),
        summary=expand(POSTERIOR / "{assembly}" / "summary.csv", assembly=ASSEMBLIES),
        predictive=expand(POSTERIOR / "{assembly}" / "predictive.csv", assembly=ASSEMBLIES),
        identified=expand(POSTERIOR / "{assembly}" / "identified.csv", assembly=ASSEMBLIES),
    output:
        figure=report(FIGURES / "fig3_8_amplitude_fit.png", caption="../report/fig3_8_amplitude_fit.rst",
                      category="3. Posterior"),
        table=POSTERIOR / "table_3_2.csv",
        markdown=POSTERIOR / "table_3_2.md",
        qsma=POSTERIOR / "qsma_vs_harmonic_balance.csv",
    params:
        code=source_hash("posterior_report.py"),
        calibrate=config.get("calibrate", {}),
        assemblies=ASSEMBLIES,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "posterior_report.tsv"
    log:
        RESULTS / "logs" / "posterior_report.log",
    script:
        "../scripts/posterior_report.py"


rule posterior:
    input:
        expand(POSTERIOR / "{assembly}" / "summary.csv", assembly=ASSEMBLIES),
        expand(FIGURES / "corner_{assembly}.png", assembly=ASSEMBLIES),
        rules.posterior_report.output,
