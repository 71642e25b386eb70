"""Acceptance numbers of the input checks: run ``python tests/benchmarks/accept_inputs.py``.

Prints, for a linear SDOF (2.2 kHz, zeta 0.02) swept 1.8 -> 2.6 kHz at 2000 Hz/s through a
24-bit ADC clipped at a fraction of the response's resonance peak, at 12.8 and 25.6 kHz:
the samples at the clipped extremes, the longest flat top (the old rule needed 3), whether
the new rule flags it, and the damping error with the clipped frames left out. Then the
false-positive count on the committed campaigns and the example campaign's base amplitude
over level_g (the level check's margin).
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from tests.io.test_clipping import _adc, _longest_flat_top, _row, _sdof_sweep  # noqa: E402

from jointcal.io import ingest_campaign, read_manifest, read_run  # noqa: E402
from jointcal.io._amplitudes import window_amplitudes
from jointcal.io._clipping import clip_levels  # noqa: E402
from jointcal.measure.modal import measure_run  # noqa: E402

ZETA = 0.02


def clipping_table() -> pd.DataFrame:
    rows = []
    for fs in (12800.0, 25600.0):
        t, base, resp, peak = _sdof_sweep(fs)
        for frac in (None, 0.99, 0.95, 0.8, 0.6, 0.5):
            r = _adc(resp, 2.0 * peak if frac is None else frac * peak)
            df = pd.DataFrame({"time_s": t, "base_accel_g": _adc(base, 4.0), "response_accel_g": r})
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                props = measure_run(df, _row(fs))[2]
            levels = clip_levels(r)
            rows.append({"fs_hz": fs, "clip_of_peak": "none" if frac is None else f"{frac:.0%}",
                         "samples_at_clip": sum(n for _, n, _ in levels),
                         "longest_flat_top": _longest_flat_top(r) if frac else 1,
                         "old_rule_flags": _longest_flat_top(r) >= 3 if frac else False,
                         "new_rule_flags": bool(levels),
                         "zeta_pr_err": props["zeta_phase_resonance"] / ZETA - 1,
                         "zeta_hp_err": props["zeta_half_power"] / ZETA - 1})
    return pd.DataFrame(rows)


def main() -> None:
    pd.set_option("display.width", 160)
    pct = {c: (lambda v: f"{v:+.1%}") for c in ("zeta_pr_err", "zeta_hp_err")}
    print(clipping_table().to_string(index=False, formatters={"fs_hz": lambda v: f"{v:.0f}", **pct}))
    repo = HERE.parents[1]
    n_flag = n_runs = 0
    ratios = []
    for camp in (repo / "raw_data", repo / "tests" / "data" / "small_campaign"):
        runs = ingest_campaign(camp, on_data_problem="flag")
        n_flag += int((runs["flags"] != "").sum())
        n_runs += len(runs)
        for row in read_manifest(camp / "manifest.csv").to_dict("records"):
            x = read_run(camp / row["file"])["base_accel_g"].to_numpy()
            amp = window_amplitudes(x, row["sample_rate_hz"], row["f_start_hz"], row["f_stop_hz"],
                                    row["sweep_rate_hz_per_s"])
            ratios.append(np.median(amp) / row["level_g"])
    ratios = np.array(ratios)
    print(f"false positives: {n_flag} flagged of {n_runs} clean runs (raw_data + small campaign)")
    print(f"base amplitude / level_g on clean runs: {ratios.min():.4f} .. {ratios.max():.4f} "
          f"(flagged beyond +/- 10 %; a units factor named within 1.5 %)")


if __name__ == "__main__":
    main()
