# Stage discrepancy: which named effect the calibrated model misses, the model with it, the gap before
# and after (jointcal.discrepancy).
# Its library holds the Ministack base-driven rig's effects: a force- or voltage-driven campaign
# (EXCITATION, common.smk) has no discrepancy target, and the README says so.


rule discrepancy_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "modal_properties.csv",
        env=expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
        best=CALIBRATION / "{assembly}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "ga_history.csv",
        validation=VALIDATION / "{assembly}" / "summary.json",
        records=assembly_records,
        kernels=ancient(KERNELS),
    output:
        diagnosis=DISCREPANCY / "{assembly}" / "diagnosis.json",
        markdown=report(DISCREPANCY / "{assembly}" / "diagnosis.md", caption="../report/discrepancy_md.rst",
                        category="5. Discrepancy", subcategory="{assembly}"),
        residuals=DISCREPANCY / "{assembly}" / "residuals.csv",
        metrics_after=DISCREPANCY / "{assembly}" / "metrics_after.csv",
        residual_figure=report(FIGURES / "discrepancy_residuals_{assembly}.png",
                               caption="../report/discrepancy_residuals.rst", category="5. Discrepancy",
                               subcategory="{assembly}"),
        before_after_figure=report(FIGURES / "discrepancy_before_after_{assembly}.png",
                                   caption="../report/discrepancy_before_after.rst", category="5. Discrepancy",
                                   subcategory="{assembly}"),
    params:
        code=source_hash("discrepancy.py"),
        discrepancy=config.get("discrepancy", {}),
        calibrate=config.get("calibrate", {}),
        validate=config.get("validate", {}),
        envelopes=config["envelopes"],
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: pool_threads
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "discrepancy_assembly" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "discrepancy" / "{assembly}.log",
    script:
        "../scripts/discrepancy.py"


rule discrepancy_table:
    input:
        best=expand(CALIBRATION / "{assembly}" / "ga_best.json", assembly=ASSEMBLIES),
        diagnosis=expand(DISCREPANCY / "{assembly}" / "diagnosis.json", assembly=ASSEMBLIES),
    output:
        table=report(DISCREPANCY / "table_3_2_corrected.html", caption="../report/table_3_2_corrected.rst",
                     category="5. Discrepancy"),
    params:
        code=source_hash("discrepancy_table.py"),
        assemblies=ASSEMBLIES,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "discrepancy_table.tsv"
    log:
        RESULTS / "logs" / "discrepancy_table.log",
    script:
        "../scripts/discrepancy_table.py"


rule discrepancy:
    input:
        expand(DISCREPANCY / "{assembly}" / "diagnosis.json", assembly=ASSEMBLIES) if EXCITATION == "base" else [],
        rules.discrepancy_table.output if EXCITATION == "base" else [],
