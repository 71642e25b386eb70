# Stage calibrate: GA (DEAP) per assembly on the paper's eq. 3.9 (jointcal.calibrate), and its figures.
# GA checkpoints live in <results>/checkpoints/ (not declared outputs: Snakemake deletes
# those before a rerun, and an interrupted GA resumes from its checkpoint).

rule calibrate_assembly:
    input:
        modal=MODAL / "modal_properties.csv",
    output:
        best=CALIBRATION / "{assembly}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "ga_history.csv",
        logbook=CALIBRATION / "{assembly}" / "ga_logbook.csv",
        curves=CALIBRATION / "{assembly}" / "model_curves.csv",
    params:
        code=source_hash("calibrate.py"),
        calibrate=config.get("calibrate", {}),
        checkpoint=lambda wc: str(RESULTS / "checkpoints" / "calibration" / f"{wc.assembly}.pkl"),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: 1
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "calibrate_assembly" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "calibrate" / "{assembly}.log",
    script:
        "../scripts/calibrate.py"


rule calibration_figures:
    input:
        history=CALIBRATION / "{assembly}" / "ga_history.csv",
        logbook=CALIBRATION / "{assembly}" / "ga_logbook.csv",
        best=CALIBRATION / "{assembly}" / "ga_best.json",
    output:
        exploration=report(FIGURES / "ga_exploration_{assembly}.png",
                           caption="../report/ga_exploration.rst", category="2. Calibration",
                           subcategory="{assembly}"),
        convergence=report(FIGURES / "ga_convergence_{assembly}.png",
                           caption="../report/ga_convergence.rst", category="2. Calibration",
                           subcategory="{assembly}"),
        caption=REPORT / "ga_{assembly}.rst",
    params:
        code=source_hash("calibration_figures.py"),
        calibrate=config.get("calibrate", {}),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "calibration_figures" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "calibration_figures" / "{assembly}.log",
    script:
        "../scripts/calibration_figures.py"


rule calibrate:
    input:
        expand(CALIBRATION / "{assembly}" / "ga_best.json", assembly=ASSEMBLIES),
        expand(FIGURES / "ga_exploration_{assembly}.png", assembly=ASSEMBLIES),
        expand(FIGURES / "ga_convergence_{assembly}.png", assembly=ASSEMBLIES),
