"""Snakemake script of rule ``posterior_assembly``: emcee around the GA optimum of one assembly.

Writes summary.csv, chain.npz, constraints.txt and predictive.csv; resumes from the chain
checkpoint in params.checkpoint when it matches. Then identified.csv: which parameters and
combinations the data identify, from the draws (jointcal.posterior.identified). Floors applied to the noise scales and
a chain stopped by max_steps before 50 tau are reported on stderr and in the log.
(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
import sys
from pathlib import Path

import numpy as np

from jointcal.calibrate import CalibrateSettings, CalibrationInputError, read_modal
from jointcal.io import write_csv_atomic
from jointcal.posterior import PosteriorSettings, run_posterior
from jointcal.posterior.identified import identified_table, unsettled


def write_identified(smk, cal: CalibrateSettings, post: PosteriorSettings) -> str:
    """identified.csv from the chain just written; returns a line for the log."""
    cal = cal.resolved(json.loads(Path(smk.input.best).read_text()))
    data = read_modal(smk.input.modal, smk.wildcards.assembly, damping=cal.damping, backbone_csv=smk.input.backbone)
    with np.load(smk.output.chain) as z:
        names = [str(n) for n in z["sample_names"]]
        why_not = unsettled({k: z[k] for k in z.files}, names, tau_factor=post.tau_factor)
        table, _ = identified_table(z["samples"], names, cal.space, data.q, data.f, data.zeta, m=cal.m,
                                    model=cal.model, viscous=cal.viscous, ratio=post.constrained_ratio,
                                    why_not=why_not, weight=data.weight)
    write_csv_atomic(table, smk.output.identified)
    return ("identified: " + ", ".join(table.loc[table["identified"], "quantity"]) + "; left to the bounds: "
            + ", ".join(table.loc[~table["identified"], "quantity"]) + (f" ({why_not})" if why_not else ""))


def main(smk) -> None:
    log = Path(smk.log[0])
    log_file = open(log, "w", buffering=1)  # line-buffered: GA/chain progress can be read while the job runs

    def progress(line: str) -> None:
        log_file.write(f"jointcal: {line}\n")

    try:
        cal = CalibrateSettings.from_config(smk.params.calibrate)
        post = PosteriorSettings.from_config(smk.params.posterior)
        res, notes = run_posterior(smk.input.modal, smk.input.scatter, smk.input.best, smk.wildcards.assembly,
                                   Path(smk.output.summary).parent, cal, post, checkpoint=smk.params.checkpoint,
                                   progress=progress, backbone_csv=smk.input.backbone)
        notes.append(write_identified(smk, cal, post))
    except (CalibrationInputError, ValueError) as exc:
        progress(str(exc))
        sys.exit(f"jointcal: {exc}")
    for n in notes:
        if "floor" in n or "NOT converged" in n:
            print(f"jointcal: warning: {n}", file=sys.stderr)
    for n in notes:
        progress(n)


main(snakemake)  # noqa: F821 (provided by Snakemake)
