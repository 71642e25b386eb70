# The report's opening summary: the verdict of the whole run (validation E, the discrepancy stage's named
# effect and what it changed, the identified quantities of the model that holds, the next test), then
# Table 3.2 and the details (jointcal.report.verdict, jointcal.report.summary). It reads
# the outputs of every stage the workflow has (common.smk's verdict_inputs; a workflow of the calibration
# and posterior stages alone gets a summary of those).


rule report_summary:
    input:
        unpack(verdict_inputs),
        runs=ingest_table,
        modal=MODAL / "modal_properties.csv",
        unit_modal=unit_files(MODAL / "{assembly}" / "{mode}" / "modal_properties.csv"),
        unit_scatter=unit_files(MODAL / "{assembly}" / "{mode}" / "scatter.csv"),
        table=POSTERIOR / "table_3_2.csv",
        history=unit_files(CALIBRATION / "{assembly}" / "{mode}" / "ga_history.csv"),
        best=unit_files(CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json"),
        chain=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "chain.npz"),
        constraints=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "constraints.txt"),
        identified=unit_files(POSTERIOR / "{assembly}" / "{mode}" / "identified.csv"),
    output:
        summary=report(REPORT / "summary.html", caption="../report/summary.rst",
                       category="0. Summary"),
        table=report(POSTERIOR / "table_3_2.html", caption="../report/table_3_2.rst", category="3. Posterior"),
        landing=REPORT / "landing.html",
    params:
        code=source_hash("report_summary.py"),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
        campaign=str(RAW_DATA),
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "report_summary.tsv"
    log:
        RESULTS / "logs" / "report_summary.log",
    script:
        "../scripts/report_summary.py"


rule summary:
    input:
        rules.report_summary.output,
