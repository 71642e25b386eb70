"""Snakemake script of rule ``validate_assembly``: simulate every run of one assembly with the
calibrated model driven by its measured base record; metrics.csv, summary.json, envelopes/.

The GA optimum gives E and the metrics; posterior draws give the predictive band only.
Runs are spread over a process pool of snakemake.threads workers. The misfit in words goes
to the log and summary.json. (No ``from __future__``: Snakemake prepends a preamble.)
"""
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.io import excitation_kind, listed_record, read_run, write_csv_atomic, write_json_atomic
from jointcal.validate import ValidateSettings, models_from_samples, validate_runs
from jointcal.validate.models import run_models
from jointcal.validate.runs import drive_gain


def main(smk) -> None:
    log = Path(smk.log[0])
    asm = smk.wildcards.assembly
    t0 = time.perf_counter()
    try:
        s = ValidateSettings.from_config(smk.params.validate)
        best = json.loads(Path(smk.input.best).read_text())
        runs = pd.read_csv(smk.input.runs, dtype={"flags": str})
        modal_table = pd.read_csv(smk.input.modal)  # this (assembly, mode)'s rows
        modal = modal_table.set_index("run_id")
        peak = modal["mode_peak_hz"] if "mode_peak_hz" in modal else pd.Series(dtype=float)
        rows = [{**r, "mode_hz": peak.get(r["run_id"])} for r in runs[runs["run_id"].isin(modal.index)].to_dict("records")]
        records = [read_run(listed_record(str(r["file"]), list(smk.input.records)), r) for r in rows]
        gain = drive_gain(modal_table) if excitation_kind(records[0]) != "base" else None
        if gain is not None:  # a force or voltage drives the mode through the campaign's modal constant
            rows = [{**r, "drive_gain": gain} for r in rows]
        models, f_ref = run_models(best, modal["f_res_hz"].to_dict(), [r["run_id"] for r in rows])
        with np.load(smk.input.chain) as z:
            samples = z["samples"]
        draws = models_from_samples(samples, float(best["m"]), s.n_draws, np.random.default_rng(s.seed),
                                    viscous=str(best.get("viscous", "dashpot")), f_ref_hz=f_ref)
        n = max(1, int(smk.threads))
        with ProcessPoolExecutor(max_workers=n) if n > 1 else _Serial() as ex:
            v = validate_runs(models, records, rows, settings=s, draws=draws, envelopes_kw=dict(smk.params.envelopes),
                              modal_kw=dict(smk.params.modal), executor=ex if n > 1 else None)
    except ValueError as exc:
        log.parent.mkdir(parents=True, exist_ok=True)
        log.write_text(f"jointcal: {exc}\n")
        sys.exit(f"jointcal: {exc}")
    out = Path(smk.output.envelopes)
    for rid, fr in v.frames.items():
        if len(fr):
            write_csv_atomic(fr, out / f"{rid}.csv")
    out.mkdir(parents=True, exist_ok=True)
    for rid, tr in v.traces.items():  # force- and voltage-driven runs: the response envelope in time
        write_csv_atomic(tr, out / "traces" / f"{rid}.csv")
    write_csv_atomic(v.metrics, smk.output.metrics)
    m = v.metrics
    words = v.words
    if gain is not None:
        words += (f" How the model is driven: the calibrated mode is driven by its modal force per unit modal mass "
                  f"A(w) r(t), the recorded {'force' if excitation_kind(records[0]) == 'force' else 'amplifier voltage'} through "
                  f"the campaign's modal constant A = {gain[0].real:.4g}{gain[0].imag:+.4g}i "
                  f"(in/s^2 per reference unit at {gain[2] / (2 * 3.141592653589793):.4g} Hz, sloped "
                  f"{abs(gain[1]) * gain[2] / abs(gain[0]):.3g} of itself per unit w/w_c), the median over the "
                  "swept-mode fits" + (": the shaker's electrical and residual dynamics in one complex gain; its "
                                       "back-EMF damping is in the calibrated mode's." if excitation_kind(records[0]) == "voltage"
                                       else "." ))
    summary = {**{k: v.error[k] for k in ("E", "E_mag", "E_phase", "n_runs", "per_level", "scale")},
               "words": words, "assembly": asm, "n_draws": len(draws),
               "median_peak_ratio": float(np.nanmedian(m["peak_ratio"])) if "peak_ratio" in m else None,
               "median_f_res_rel_err": float(np.nanmedian(m["f_res_rel_err"])) if "f_res_rel_err" in m else None,
               "median_zeta_rel_err": float(np.nanmedian(m["zeta_rel_err"])) if "zeta_rel_err" in m else None,
               "model": {k: best[k] for k in ("Fs", "KT", "chi", "beta", "k", "zeta_v", "m", "viscous")},
               "settings": dict(smk.params.validate), "wall_s": time.perf_counter() - t0}
    write_json_atomic(summary, smk.output.summary)
    lines = [f"jointcal: {asm}: {words}"]
    lines += [f"jointcal: warning: {r.run_id}: not validated: {r.note}" for r in m.itertuples() if r.n_frames == 0]
    for line in lines[1:]:
        print(line, file=sys.stderr)
    t = m[m["n_frames"] > 0]
    lines.append(f"jointcal: {len(m)} runs, {len(draws)} posterior draws, {n} workers, {summary['wall_s']:.1f} s wall; "
                 f"per run: optimum simulation + processing {t['sim_s'].mean():.2f} s, posterior draws "
                 f"{t['draws_s'].mean():.2f} s")
    log.write_text("\n".join(lines) + "\n")


class _Serial:
    """A stand-in for a one-worker pool (no executor)."""

    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


main(snakemake)  # noqa: F821 (provided by Snakemake)
