"""The real beam's dwell records as a campaign in the contract, and its ring-down backbone against the chirps'.

Run:  python tests/benchmarks/real_dwell_campaign.py OUT [--workflow]

Writes ``OUT/manifest.csv`` pointing at the five Test.Lab exports of `../shared/real/unesp-bert-dwell-mode1/`
(relative paths; nothing copied), voltage-driven at 0.15 V:

- the response is ``Time Acc1:+X``, the accelerometer at the tip beside the laser (Test.Lab stores it in m/s^2
  and says so; its steady amplitude, 110 m/s^2 at 18 Hz, and the laser's, 0.97 m/s, describe one motion of
  8.6 mm); the drive is ``Time Shaker:-X`` of the run's ``*_TimeShaker.mat``, named in ``reference_file``;
- 17-20 Hz are ``dwell`` runs (the steady point, and the ring-down after the cut); the lab has no drive file for
  16 Hz, which is a ``ringdown`` run (its decay's start from the response).

With ``--workflow`` it runs ``snakemake --cores 1 modal --config raw_data=OUT results=OUT/results`` with the
default config. Then it reads ``OUT/results/modal/backbone.csv`` (or reads the records itself with the modal
stage's functions when the workflow was not run) and prints the ring-down backbone against the sweep-fit
backbone of the six chirps of `../shared/real/unesp-bert-mode1/` where their amplitudes overlap. Skips, saying
why, when the records are absent.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[2]
REAL = Path(os.environ.get("JOINTCAL_REAL_DATA", REPO.parent / "shared" / "real"))
DWELL, CHIRPS = REAL / "unesp-bert-dwell-mode1", REAL / "unesp-bert-mode1"
FREQS = (16, 17, 18, 19, 20)


def write_campaign(out: Path) -> Path:
    """OUT/manifest.csv for the five dwell records (paths relative to OUT)."""
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for i, f in enumerate(FREQS):
        shaker = DWELL / f"Sine_{f}Hz_TimeShaker.mat"
        has_drive = shaker.is_file()
        rows.append({"run_id": f"dwell_{f}Hz", "assembly": "bert", "sequence": i + 1, "level_V": 0.15,
                     "test": "dwell" if has_drive else "ringdown", "dwell_hz": f if has_drive else "",
                     "direction": "", "f_start_hz": "", "f_stop_hz": "", "sweep_rate_hz_per_s": "",
                     "sample_rate_hz": 1024.0, "file": os.path.relpath(DWELL / f"Sine_{f}Hz_Time.mat", out),
                     "reference_file": os.path.relpath(shaker, out) if has_drive else "",
                     "reference_channel": "Time Shaker:-X" if has_drive else "", "response_channel": "Time Acc1:+X",
                     "notes": "" if has_drive else "no drive file: read as a ring-down"})
    pd.DataFrame(rows).to_csv(out / "manifest.csv", index=False)
    return out / "manifest.csv"


def backbone_here(out: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The dwell campaign's backbone points and modal table, read with the modal stage's functions (no workflow)."""
    from jointcal.io import ingest_campaign, read_run
    from jointcal.measure.campaign import campaign_modal
    from jointcal.measure.testkinds.read import backbone_table

    runs = ingest_campaign(out)
    points: list = []
    rows, _, _ = campaign_modal(runs, lambda r: (None, {}, read_run(out / r["file"], r)), {}, points=points)
    return backbone_table(pd.DataFrame(rows), points), pd.DataFrame(rows)


def compare(bb: pd.DataFrame, modal: pd.DataFrame) -> None:
    """Print, per chirp, the ring-down windows (their median) and the dwell points within 30% of its amplitude
    beside its sweep fit, and the differences."""
    from jointcal.io import read_manifest, read_run
    from jointcal.measure.modal import measure_run

    rd = bb[bb["test"] == "ringdown"]
    for rid, g in rd.groupby("run_id", sort=False):
        print(f"{rid}: {len(g)} ring-down windows, q {g['q_in'].max():.3g}-{g['q_in'].min():.3g} in "
              f"({np.log10(g['q_in'].max() / g['q_in'].min()):.2f} decades), f {g['f_hz'].min():.4f}-"
              f"{g['f_hz'].max():.4f} Hz, zeta {g['zeta'].min():.4f}-{g['zeta'].max():.4f}")
    for _, p in bb[bb["test"] == "dwell"].iterrows():
        print(f"{p['run_id']}: dwell point q {p['q_in']:.4g} in, f {p['f_hz']:.4f} Hz, zeta {p['zeta']:.4f}")
    if "f_dwell_quad_hz" in modal:
        for (lev, q), g in modal[modal["f_res_method"] == "dwell"].groupby(["level_V", "q_dwell_quad_in"]):
            r = g.iloc[0]
            print(f"dwells at {lev:g} V ({len(g)}): phase resonance {r['f_dwell_quad_hz']:.4f} Hz, zeta "
                  f"{r['zeta_dwell_quad']:.4f} at q {q:.4f} in")
    print("\nchirp (sweep fit)                           | ring-down windows within 30% of its q_in")
    for _, row in read_manifest(CHIRPS / "manifest.csv").iterrows():
        row = row.to_dict()
        p = measure_run(read_run(CHIRPS / row["file"], row), row)[2]
        near = rd[(rd["q_in"] > p["q_in"] / 1.3) & (rd["q_in"] < p["q_in"] * 1.3)]
        line = f"{row['run_id']}: q {p['q_in']:.3f} f {p['f_res_hz']:.4f} zeta {p['zeta_res']:.4f} | "
        if len(near):
            f_rd, z_rd = near["f_hz"].median(), near["zeta"].median()
            line += (f"n {len(near):2d} f {f_rd:.4f} zeta {z_rd:.4f}: df {100 * (f_rd / p['f_res_hz'] - 1):+.3f}%, "
                     f"dzeta {100 * (z_rd / p['zeta_res'] - 1):+.1f}%")
        else:
            line += "no ring-down window at this amplitude"
        dw = bb[(bb["test"] == "dwell") & (bb["q_in"] > p["q_in"] / 1.3) & (bb["q_in"] < p["q_in"] * 1.3)]
        for _, d in dw.iterrows():
            line += (f" | dwell {d['run_id']}: q {d['q_in']:.3f} df {100 * (d['f_hz'] / p['f_res_hz'] - 1):+.3f}%, "
                     f"dzeta {100 * (d['zeta'] / p['zeta_res'] - 1):+.1f}%")
        print(line)


def main(argv: list[str]) -> int:
    if not argv or argv[0].startswith("-"):
        print(__doc__.splitlines()[2])
        return 2
    if not (DWELL.is_dir() and (CHIRPS / "manifest.csv").is_file()):
        print(f"skipped: the real records are not at {REAL} (they are not part of the repository)")
        return 0
    out = Path(argv[0]).resolve()
    print(f"wrote {write_campaign(out)}")
    if "--workflow" in argv:
        cmd = [sys.executable, "-m", "snakemake", "--cores", "1", "modal", "--config", f"raw_data={out}",
               f"results={out / 'results'}"]
        print(" ".join(cmd[1:]))
        done = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
        if done.returncode:
            print(done.stderr[-3000:])
            return done.returncode
        bb = pd.read_csv(out / "results" / "modal" / "backbone.csv")
        modal = pd.read_csv(out / "results" / "modal" / "modal_properties.csv")
    else:
        bb, modal = backbone_here(out)
    compare(bb, modal)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
