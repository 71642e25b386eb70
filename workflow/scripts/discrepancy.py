"""Snakemake script of rule ``discrepancy_assembly``: diagnose one assembly (jointcal.discrepancy).

Writes diagnosis.json, diagnosis.md, residuals.csv, metrics_after.csv and the two figures;
a bad input ends the job with one sentence in the log and on stderr. The revalidation runs
on a process pool of snakemake.threads workers. (No ``from __future__``: Snakemake prepends
a preamble to scripts.)
"""
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd

from jointcal.calibrate import CalibrateSettings
from jointcal.discrepancy import DiscrepancySettings, diagnose, diagnosis_markdown
from jointcal.discrepancy.stage import valley_starts
from jointcal.io import listed_record, read_run, write_bytes_atomic, write_csv_atomic, write_json_atomic
from jointcal.report.discrepancy import before_after_figure, residual_map_figure
from jointcal.validate import ValidateSettings


def main(smk) -> None:
    log = Path(smk.log[0])
    log.parent.mkdir(parents=True, exist_ok=True)
    asm = smk.wildcards.assembly
    lines = []

    def say(s):
        lines.append(f"jointcal: {s}")
        log.write_text("\n".join(lines) + "\n")

    try:
        settings = DiscrepancySettings.from_config(smk.params.discrepancy)
        runs = pd.read_csv(smk.input.runs, dtype={"flags": str})
        modal = pd.read_csv(smk.input.modal, dtype={"flags": str})  # this (assembly, mode)'s rows
        rows = runs[runs["run_id"].isin(modal["run_id"])].to_dict("records")
        env_dir = Path(smk.input.env[0]).parent
        envs = {r["run_id"]: pd.read_csv(env_dir / f"{r['run_id']}.csv") for r in rows
                if (env_dir / f"{r['run_id']}.csv").is_file()}
        records = [read_run(listed_record(str(r["file"]), list(smk.input.records)), r) for r in rows]
        best = json.loads(Path(smk.input.best).read_text())
        summary = json.loads(Path(smk.input.validation).read_text())
        space = CalibrateSettings.from_config(smk.params.calibrate).resolved(best).space
        starts = valley_starts(pd.read_csv(smk.input.history), best)
        before_dir = Path(smk.input.validation).parent / "envelopes"
        before = {p.stem: pd.read_csv(p) for p in before_dir.glob("*.csv")}
        n = max(1, int(smk.threads))
        with ProcessPoolExecutor(max_workers=n) as ex:
            out = diagnose(asm, envs, modal, best, summary.get("scale"), records, rows, space=space,
                           settings=settings, validate_settings=ValidateSettings.from_config(smk.params.validate),
                           envelopes_kw=dict(smk.params.envelopes), modal_kw=dict(smk.params.modal),
                           metric_before=float(summary["E"]), frames_before=before, joint_starts=starts,
                           executor=ex if n > 1 else None, log=say)
    except (ValueError, KeyError) as exc:
        say(f"{asm}: {exc}")
        sys.exit(f"jointcal: {asm}: {exc}")
    d = out["diagnosis"]
    write_csv_atomic(out["residuals"], smk.output.residuals)
    write_csv_atomic(out["validation_after"].metrics, smk.output.metrics_after)
    write_bytes_atomic(diagnosis_markdown(d).encode(), smk.output.markdown)
    tmp_fig = Path(smk.output.residual_figure)
    residual_map_figure(out["residuals"], d, tmp_fig)
    before_after_figure(before, out["validation_after"].frames, d, Path(smk.output.before_after_figure))
    write_json_atomic(d, smk.output.diagnosis)
    say(f"{asm}: {d['effect']} ({d['confidence']}); E {d['metric_before']:.2f} -> {d['metric_after']:.2f}; "
        f"{d['seconds']:.0f} s")


main(snakemake)  # noqa: F821 (provided by Snakemake)
