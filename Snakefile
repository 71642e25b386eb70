# jointcal workflow: swept-sine shaker campaign -> calibrated Iwan joint models.
# Stages, in the order data flows (workflow/rules/<stage>.smk; logic in src/jointcal/):
#   ingest     validate the campaign (manifest + run files) -> <results>/ingest/runs.csv
#   envelopes  drive ridge + complex amplitudes per run     -> <results>/envelopes/<run_id>.csv
#   modal      resonance, damping, scatter, figures          -> <results>/modal/modal_properties.csv
#
# Everything:      snakemake --cores 2      (a bare `snakemake` uses profiles/default/)
# One stage:       snakemake --cores 2 ingest
# Other campaign:  snakemake --cores 2 --config raw_data=PATH/TO/CAMPAIGN results=PATH
from snakemake.utils import min_version, validate

min_version("8.0")


configfile: "workflow/config/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/ingest.smk"
include: "workflow/rules/envelopes.smk"
include: "workflow/rules/modal.smk"


rule all:
    default_target: True
    input:
        RESULTS / "ingest" / "runs.csv",
        rules.modal.input,
