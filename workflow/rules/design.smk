# Stage design: which test to run next (jointcal.design), from each assembly's posterior through the
# fast steady-state model; next_test.json/.csv/.md and a figure. A force- or voltage-driven campaign
# gets the same files saying in words what cannot be recommended.


rule design_assembly:
    input:
        runs=INGEST / "runs.csv",
        modal=MODAL / "modal_properties.csv",
        scatter=MODAL / "scatter.csv",
        best=CALIBRATION / "{assembly}" / "ga_best.json",
        chain=POSTERIOR / "{assembly}" / "chain.npz",
        identified=POSTERIOR / "{assembly}" / "identified.csv",
        kernels=ancient(KERNELS),
    output:
        json=DESIGN / "{assembly}" / "next_test.json",
        csv=DESIGN / "{assembly}" / "next_test.csv",
        markdown=report(DESIGN / "{assembly}" / "next_test.md", caption="../report/next_test_md.rst",
                        category="6. Next test", subcategory="{assembly}"),
        figure=report(FIGURES / "next_test_{assembly}.png", caption="../report/next_test.rst",
                      category="6. Next test", subcategory="{assembly}"),
    params:
        code=source_hash("design.py"),
        design=config.get("design", {}),
        calibrate=config.get("calibrate", {}),
        posterior=config.get("posterior", {}),
        modal=config["modal"],
    wildcard_constraints:
        assembly=ASSEMBLY_RE,
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "design_assembly" / "{assembly}.tsv"
    log:
        RESULTS / "logs" / "design" / "{assembly}.log",
    script:
        "../scripts/design.py"


rule design:
    input:
        expand(DESIGN / "{assembly}" / "next_test.json", assembly=ASSEMBLIES),
        expand(FIGURES / "next_test_{assembly}.png", assembly=ASSEMBLIES),
