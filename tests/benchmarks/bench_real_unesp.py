"""Opt-in benchmark on real records: the UNESP-BERT bolted beam, mode 1, six voltage-driven up chirps.

Run:  python tests/benchmarks/bench_real_unesp.py [CAMPAIGN_DIR]

The records are not in this repository (their licence differs; see ../shared/real/README.md):
the default folder is ../shared/real/unesp-bert-mode1 beside the repository, and the benchmark
says so and stops when it is absent. Data: SHM Lab, UNESP Ilha Solteira (UNESP-BERT; Teloli et
al., Mech. Syst. Signal Process. 159 (2021) 107751), non-commercial research use.

Printed per run: jointcal's read-out (method, q_in, f_res_hz, zeta_res, misfit), the response's
band-passed envelope peak computed here independently (a 2nd-order Butterworth band-pass over
0.7-1.3 f_res, zero-phase, and the Hilbert envelope over (2 pi f_res)^2), the lab-style H1
read-outs of the same record (the |H1| peak line and the FRF fit's pole), and the modal stage's
time per run. Checked: every run finite, q_in within 5% of the band-passed peak, and the
resonance falling monotonically with level.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from jointcal.io import read_manifest, read_run
from jointcal.measure.frf import h1_estimate
from jointcal.measure.modal import measure_run
from jointcal.models import G

DEFAULT = Path(__file__).resolve().parents[3] / "shared" / "real" / "unesp-bert-mode1"


def band_passed_peak(resp_g: np.ndarray, fs: float, f_hz: float) -> float:
    """Peak of the response's band-passed Hilbert envelope as a displacement (in)."""
    a = np.nan_to_num(resp_g) * G
    sos = signal.butter(2, [0.7 * f_hz, 1.3 * f_hz], btype="band", fs=fs, output="sos")
    env = np.abs(signal.hilbert(signal.sosfiltfilt(sos, a - np.median(a))))
    return float(env.max() / (2 * np.pi * f_hz) ** 2)


def h1_peak(ref: np.ndarray, resp_g: np.ndarray, fs: float, f_hz: float) -> float:
    """The lab's read-out: the line of the whole-record H1's largest magnitude within 0.7-1.3 f_hz (Hz)."""
    h = h1_estimate(np.nan_to_num(ref), np.nan_to_num(resp_g), fs)
    f = h["freq_hz"].to_numpy()
    near = (f > 0.7 * f_hz) & (f < 1.3 * f_hz)
    mag = np.abs(h["h1_re"] + 1j * h["h1_im"]).to_numpy()
    return float(f[near][np.argmax(mag[near])])


def main(folder: Path) -> pd.DataFrame | None:
    if not (folder / "manifest.csv").is_file():
        print(f"skipped: the real records are not at {folder} (they are not part of this repository; give their "
              "folder as the first argument).")
        return None
    man = read_manifest(folder / "manifest.csv")
    rows = []
    for _, row in man.iterrows():
        row = row.to_dict()
        rec = read_run(folder / row["file"], row)
        t0 = time.perf_counter()
        _, _, p = measure_run(rec, row)
        dt = time.perf_counter() - t0
        q_bp = band_passed_peak(rec["response_accel_g"].to_numpy(float), float(row["sample_rate_hz"]), p["f_res_hz"])
        rows.append(dict(run_id=row["run_id"], level_V=row["level_V"], method=p["f_res_method"], eta=p["eta"],
                         q_in=p["q_in"], q_band_passed=q_bp, q_ratio=p["q_in"] / q_bp, f_res_hz=p["f_res_hz"],
                         zeta_res=p["zeta_res"], misfit=p["sweep_residual"],
                         h1_peak_hz=h1_peak(rec["drive_V"].to_numpy(float), rec["response_accel_g"].to_numpy(float),
                                            float(row["sample_rate_hz"]), p["f_res_hz"]),
                         h1_fit_hz=p["f_frf_hz"], h1_zeta=p["zeta_frf"], flags=p["flags"], seconds=dt))
    t = pd.DataFrame(rows).sort_values("level_V")
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(t.to_string(index=False, float_format=lambda v: f"{v:.5g}"))
    finite = np.isfinite(t[["q_in", "f_res_hz", "zeta_res"]].to_numpy()).all()
    q_ok = (t["q_ratio"] - 1).abs().max() <= 0.05
    mono = bool(np.all(np.diff(t["f_res_hz"].to_numpy()) < 0))
    h1, pk = t["h1_fit_hz"].to_numpy(), t["h1_peak_hz"].to_numpy()
    print(f"\nfinite: {finite}; q_in within 5% of the band-passed envelope peak: {q_ok} (worst "
          f"{100 * (t['q_ratio'] - 1).abs().max():.1f}%); resonance falls monotonically with level: {mono} "
          f"({t['f_res_hz'].iloc[0]:.3f} -> {t['f_res_hz'].iloc[-1]:.3f} Hz, "
          f"{100 * (t['f_res_hz'].iloc[-1] / t['f_res_hz'].iloc[0] - 1):+.2f}%); the lab's H1 peak line "
          f"{pk[0]:.3f} -> {pk[-1]:.3f} Hz, its FRF fit {h1[0]:.3f} -> {h1[-1]:.3f} Hz (a fast up chirp's H1 leans "
          "toward the sweep direction); "
          f"modal stage {t['seconds'].median():.2f} s per run (median, numba cache "
          f"warm after the first: {t['seconds'].iloc[0]:.2f} s)")
    return t


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT)
