"""Snakemake script of rule ``design_assembly``: one assembly's next test and its figure.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
from pathlib import Path

import pandas as pd

from jointcal._stage_job import stage_job
from jointcal.calibrate import CalibrateSettings, read_modal
from jointcal.design import DesignSettings, run_design
from jointcal.io import write_bytes_atomic
from jointcal.posterior import PosteriorSettings
from jointcal.report.design import design_figure

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    smk, asm = job.smk, job.smk.wildcards.assembly
    cal = CalibrateSettings.from_config(smk.params.calibrate)
    post = PosteriorSettings.from_config(smk.params.posterior)
    rec, ranked = run_design(smk.input.runs, smk.input.modal, smk.input.scatter, smk.input.best, smk.input.chain,
                             smk.input.identified, asm, Path(smk.output.json).parent, cal,
                             DesignSettings.from_config(smk.params.design),
                             eta_max=float(smk.params.modal.get("eta_max", 0.5)), floors=dict(post.rel_std_floor))
    data = read_modal(smk.input.modal, asm, damping=cal.resolved(json.loads(Path(smk.input.best).read_text())).damping)
    measured = pd.DataFrame({"level": data.level, "f_hz": data.f, "zeta": data.zeta, "q_in": data.q})
    write_bytes_atomic(design_figure(rec, ranked, measured, pd.read_csv(smk.input.identified)), smk.output.figure)
    r = rec["recommended"]
    line = (f"recommended {r['level_g']:g} g {r['direction']} at {r['sweep_rate_hz_per_s']:g} Hz/s; predicted width "
            "ratios " + ", ".join(f"{k} {v:.3g}" for k, v in rec["predicted_width_ratio"].items())
            if r else f"no level recommended: {rec['reason']}")
    job.log(f"{asm}: {line} ({job.elapsed:.1f} s)")
