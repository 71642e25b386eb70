# Stage calibrate: GA (DEAP) per assembly on the paper's eq. 3.9 (jointcal.calibrate), and its figures.
# GA checkpoints live in <results>/checkpoints/ (not declared outputs: Snakemake deletes
# those before a rerun, and an interrupted GA resumes from its checkpoint).

# One (assembly, mode)'s rows of the modal tables (and its runs' backbone points): what that unit's stages read.
rule modal_unit:
    input:
        table=MODAL / "modal_properties.csv",
        scatter=MODAL / "scatter.csv",
        backbone=MODAL / "backbone.csv",
    output:
        table=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        scatter=MODAL / "{assembly}" / "{mode}" / "scatter.csv",
        backbone=MODAL / "{assembly}" / "{mode}" / "backbone.csv",
    params:
        code=source_hash("modal_unit.py"),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "modal_unit" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "modal_unit" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/modal_unit.py"


rule calibrate_assembly:
    input:
        modal=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        backbone=MODAL / "{assembly}" / "{mode}" / "backbone.csv",  # ring-down windows, dwells' phase resonance
    output:
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "{mode}" / "ga_history.csv",
        logbook=CALIBRATION / "{assembly}" / "{mode}" / "ga_logbook.csv",
        curves=CALIBRATION / "{assembly}" / "{mode}" / "model_curves.csv",
    params:
        code=source_hash("calibrate.py"),
        calibrate=config.get("calibrate", {}),
        checkpoint=lambda wc: str(RESULTS / "checkpoints" / "calibration" / f"{wc.assembly}_{wc.mode}.pkl"),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "calibrate_assembly" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "calibrate" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/calibrate.py"


rule calibration_figures:
    input:
        history=CALIBRATION / "{assembly}" / "{mode}" / "ga_history.csv",
        logbook=CALIBRATION / "{assembly}" / "{mode}" / "ga_logbook.csv",
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
    output:
        exploration=report(FIGURES / "ga_exploration_{assembly}_{mode}.png",
                           caption="../report/ga_exploration.rst", category="2. Calibration",
                           subcategory="{assembly} {mode}"),
        convergence=report(FIGURES / "ga_convergence_{assembly}_{mode}.png",
                           caption="../report/ga_convergence.rst", category="2. Calibration",
                           subcategory="{assembly} {mode}"),
        caption=REPORT / "ga_{assembly}_{mode}.rst",
    params:
        code=source_hash("calibration_figures.py"),
        calibrate=config.get("calibrate", {}),
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "calibration_figures" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "calibration_figures" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/calibration_figures.py"


rule calibrate:
    input:
        unit_files(CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json"),
        unit_files(FIGURES / "ga_exploration_{assembly}_{mode}.png"),
        unit_files(FIGURES / "ga_convergence_{assembly}_{mode}.png"),
