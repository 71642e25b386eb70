# Stage design: which test to run next (jointcal.design), from each assembly's posterior through the
# fast steady-state model; next_test.json/.csv/.md and a figure. A force- or voltage-driven campaign
# gets the same files saying in words what cannot be recommended.


rule design_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "{assembly}" / "{mode}" / "modal_properties.csv",
        scatter=MODAL / "{assembly}" / "{mode}" / "scatter.csv",
        best=CALIBRATION / "{assembly}" / "{mode}" / "ga_best.json",
        chain=POSTERIOR / "{assembly}" / "{mode}" / "chain.npz",
        identified=POSTERIOR / "{assembly}" / "{mode}" / "identified.csv",
        kernels=ancient(KERNELS),
    output:
        json=DESIGN / "{assembly}" / "{mode}" / "next_test.json",
        csv=DESIGN / "{assembly}" / "{mode}" / "next_test.csv",
        markdown=report(DESIGN / "{assembly}" / "{mode}" / "next_test.md", caption="../report/next_test_md.rst",
                        category="6. Next test", subcategory="{assembly} {mode}"),
        figure=report(FIGURES / "next_test_{assembly}_{mode}.png", caption="../report/next_test.rst",
                      category="6. Next test", subcategory="{assembly} {mode}"),
    params:
        code=source_hash("design.py"),
        design=config.get("design", {}),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
        mode=MODE_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "design_assembly" / "{assembly}" / "{mode}.tsv"
    log:
        RESULTS / "logs" / "design" / "{assembly}" / "{mode}.log",
    script:
        "../scripts/design.py"


rule design:
    input:
        unit_files(DESIGN / "{assembly}" / "{mode}" / "next_test.json"),
        unit_files(FIGURES / "next_test_{assembly}_{mode}.png"),
