# Stage discrepancy: which named effect the calibrated model misses, the model with it, the gap before
# and after (jointcal.discrepancy).
# It runs for every excitation and model kind: each kind tries its own library (jointcal.effects, kinds).


rule discrepancy_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        backbone=MODAL / "{assembly}" / "{mode}" / "backbone.csv",  # ring-down windows, dwells' phase resonance
        env=expand(ENVELOPES / "{run_id}.csv", run_id=RUN_IDS),
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
        history=CALIBRATION / "{assembly}" / "{mode}" / "ga_history.csv",
        validation=VALIDATION / "{assembly}" / "{mode}" / "summary.json",
        records=assembly_records,
        kernels=ancient(KERNELS),
    output:
        diagnosis=DISCREPANCY / "{assembly}" / "{mode}" / "diagnosis.json",
        markdown=report(DISCREPANCY / "{assembly}" / "{mode}" / "diagnosis.md", caption="../report/discrepancy_md.rst",
                        category="5. Discrepancy", subcategory="{assembly} {mode}"),
        residuals=DISCREPANCY / "{assembly}" / "{mode}" / "residuals.csv",
        metrics_after=DISCREPANCY / "{assembly}" / "{mode}" / "metrics_after.csv",
        residual_figure=report(FIGURES / "discrepancy_residuals_{assembly}_{mode}.png",
                               caption="../report/discrepancy_residuals.rst", category="5. Discrepancy",
                               subcategory="{assembly} {mode}"),
        before_after_figure=report(FIGURES / "discrepancy_before_after_{assembly}_{mode}.png",
                                   caption="../report/discrepancy_before_after.rst", category="5. Discrepancy",
                                   subcategory="{assembly} {mode}"),
    params:
        code=source_hash("discrepancy.py"),
        discrepancy=config.get("discrepancy", {}),
        calibrate=config.get("calibrate", {}),
        validate=config.get("validate", {}),
        envelopes=config["envelopes"],
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: pool_threads
    priority: 10  # on the longest chain of jobs (figures and tables fill the gaps)
    benchmark:
        RESULTS / "benchmarks" / "discrepancy_assembly" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "discrepancy" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/discrepancy.py"


rule discrepancy_table:
    input:
        best=unit_files(CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json"),
        diagnosis=unit_files(DISCREPANCY / "{assembly}" / "{mode}" / "diagnosis.json"),
    output:
        table=report(DISCREPANCY / "table_3_2_corrected.html", caption="../report/table_3_2_corrected.rst",
                     category="5. Discrepancy"),
    params:
        code=source_hash("discrepancy_table.py"),
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "discrepancy_table.tsv"
    log:
        RESULTS / "logs" / "discrepancy_table.log",
    script:
        "../scripts/discrepancy_table.py"


rule discrepancy:
    input:
        unit_files(DISCREPANCY / "{assembly}" / "{mode}" / "diagnosis.json"),
        rules.discrepancy_table.output,
