"""Snakemake script of rule ``design_assembly``: one assembly's next test and its figure.

(No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import json
import sys
import time
from pathlib import Path

import pandas as pd

from jointcal.calibrate import CalibrateSettings, CalibrationInputError, read_modal
from jointcal.design import DesignSettings, run_design
from jointcal.io import write_bytes_atomic
from jointcal.posterior import PosteriorSettings
from jointcal.report.design import design_figure


def main(smk) -> None:
    t0 = time.perf_counter()
    log = Path(smk.log[0])
    try:
        cal = CalibrateSettings.from_config(smk.params.calibrate)
        post = PosteriorSettings.from_config(smk.params.posterior)
        settings = DesignSettings.from_config(smk.params.design)
        rec, ranked = run_design(smk.input.runs, smk.input.modal, smk.input.scatter, smk.input.best, smk.input.chain,
                                 smk.input.identified, smk.wildcards.assembly, Path(smk.output.json).parent, cal,
                                 settings, eta_max=float(smk.params.modal.get("eta_max", 0.5)),
                                 floors=dict(post.rel_std_floor))
        best = json.loads(Path(smk.input.best).read_text())
        data = read_modal(smk.input.modal, smk.wildcards.assembly, damping=cal.resolved(best).damping)
        measured = pd.DataFrame({"level": data.level, "f_hz": data.f, "zeta": data.zeta, "q_in": data.q})
        write_bytes_atomic(design_figure(rec, ranked, measured, pd.read_csv(smk.input.identified)), smk.output.figure)
    except (CalibrationInputError, ValueError) as exc:
        log.write_text(f"jointcal: {exc}\n")
        sys.exit(f"jointcal: {exc}")
    r = rec["recommended"]
    line = (f"recommended {r['level_g']:g} g {r['direction']} at {r['sweep_rate_hz_per_s']:g} Hz/s; predicted width "
            "ratios " + ", ".join(f"{k} {v:.3g}" for k, v in rec["predicted_width_ratio"].items())
            if r else f"no level recommended: {rec['reason']}")
    log.write_text(f"jointcal: {smk.wildcards.assembly}: {line} ({time.perf_counter() - t0:.1f} s)\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
