# jointcal workflow: swept-sine shaker campaign -> calibrated Iwan joint models.
# Stages, in the order data flows (workflow/rules/<stage>.smk; logic in src/jointcal/):
#   (kernels  numba kernels compiled once, beside ingest      -> <results>/kernels/numba.txt)
#   ingest     validate the campaign (manifest + run files) -> <results>/ingest/runs.csv
#   envelopes  drive ridge + complex amplitudes per run     -> <results>/envelopes/<run_id>.csv
#   modal      resonance, damping, scatter, figures, FRFs    -> <results>/modal/modal_properties.csv, frf/
#   calibrate  GA (DEAP) on eq. 3.9 per assembly + polish     -> <results>/calibration/<assembly>/ga_best.json
#   posterior  emcee around the optimum, Table 3.2, Fig. 3.8  -> <results>/posterior/<assembly>/summary.csv
#   validate   model driven by the measured base, Fig. 3.11   -> <results>/validation/<assembly>/summary.json
#   discrepancy  the missing effect named, E before and after -> <results>/discrepancy/<assembly>/diagnosis.json
#   design     the next test, predicted from the posterior     -> <results>/design/<assembly>/next_test.json
#   summary    the report's opening verdict                    -> <results>/report/summary.html
#
# Everything:      snakemake --cores 2      (a bare `snakemake` uses profiles/default/)
# One stage:       snakemake --cores 2 ingest
# Other campaign:  snakemake --cores 2 --config raw_data=PATH/TO/CAMPAIGN results=PATH
# Nested settings: snakemake --cores 2 --configfile my.yaml   (merged over workflow/config/config.yaml)
# After a kill:    snakemake --unlock; snakemake --cores 2 --rerun-incomplete   (GA and chain resume)
# On SLURM:        snakemake --workflow-profile workflow/profiles/slurm   (pip install -e ".[slurm]")
# Report:          snakemake --report results/report.html
from snakemake.utils import min_version

min_version("8.0")


configfile: "workflow/config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"  # checks and validates the config first
include: "workflow/rules/kernels.smk"
include: "workflow/rules/ingest.smk"
include: "workflow/rules/envelopes.smk"
include: "workflow/rules/modal.smk"
include: "workflow/rules/calibrate.smk"
include: "workflow/rules/posterior.smk"
include: "workflow/rules/validate.smk"
include: "workflow/rules/discrepancy.smk"
include: "workflow/rules/design.smk"
include: "workflow/rules/summary.smk"


rule all:
    default_target: True
    input:
        INGEST / "runs.csv",
        KERNELS,  # compiled beside the modal stage, before the jobs its table names
        rules.modal.input,
        rules.calibrate.input,
        rules.posterior.input,
        rules.validate.input,
        rules.discrepancy.input,
        rules.design.input,
        rules.summary.input,
