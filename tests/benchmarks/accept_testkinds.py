"""Acceptance of the ring-down and dwell read-outs on the virtual lab (issue 31): one truth, three kinds of test.

Run:  python tests/benchmarks/accept_testkinds.py [--seeds 1,2,3] [--out FILE] [--rigs 'beam force,...']

For each rig -- the jointed beam of `tests/_support/rigs.py` (100 Hz, its Iwan joint, a second linear mode at
230 Hz, on its small open-loop shaker) with a force and with a voltage reference, and the base-driven Ministack
(`jointcal.synth.DEFAULT_SPEC`'s first assembly) -- one virtual campaign (`jointcal.synth.generate`: the exact-Iwan
time simulation, the shaker, the DAQ, 0.1% noise of each channel's rms, as in tests/synth/test_steady.py: a
ring-down's decades end at its noise floor, and 2% would leave half a decade)
holds a ring-down cut off from a dwell at the top level's resonance, five dwells around the middle level's
resonance (each with its own ring-down after the cut), and slow sweeps (eta 0.5) at three levels. Each run is
read by the modal stage's functions (`tests/_support/campaign.modal_tables`), every point set beside
the rig's truth at its own amplitude: the structure's first-harmonic balance (force: response / force is the
structure alone; base: the Ministack's) or the coupled rig's pole (voltage: response / voltage holds the shaker).

Printed per rig and seed: the ring-downs' decades and largest |f| and |zeta| errors; the dwells' phase
resonance; the sweeps'; and the kinds on one backbone: each sweep's and dwell level's frequency against the
ring-downs' at its amplitude (a line in log q through the windows within a factor `NEAR` of it, three or more).

Acceptance (issue 31): ring-down f within 0.1%, zeta within 3% over >= 1.5 decades; dwells within 0.05% / 2%;
the kinds on one backbone within 0.1%.

Measured 2026-11-26, seeds 1-3, loaded 2-core machine (load average 5-7; worst over every decay window: the
ring-down run's and the five dwells' own decays; %):

    rig             ring-down run decades  decay f  decay zeta  dwell f   dwell zeta  sweep f  one backbone f
    beam voltage    1.54-1.66              0.031    1.5-2.2     0.0009    0.88        0.0076   0.0077
    ministack base  1.81-2.04              0.095-0.100  2.4-3.0  0.0011    0.11        0.0021   0.077

Again 2026-11-26 after the decay's continuation ran on at its junction's frequency and decay rate
(`jointcal.measure.ringdown._continued`), seeds 1-3, the machine shared with two other jobs:

    rig             ring-down run decades  decay f      decay zeta  dwell f   dwell zeta  sweep f  one backbone f
    beam voltage    1.54-1.66              0.024-0.032  1.5-2.2     0.0009    0.88        0.0076   0.0073
    ministack base  1.80-2.04              0.033-0.039  2.4-3.0     0.0011    0.11        0.0021   0.050
    beam force      1.51-1.56              0.018-0.028  1.9-2.4     0.0032    0.39        0.0077   0.018
    beam force      1.51-1.56              0.028    1.9-2.4     0.0032    0.39        0.0077   0.018

Again 2026-11-26 (15:00 UTC, branch zeta2) with the windows grown towards `ZETA_SE_AIM` (0.5% standard error of
the decay rate, within `SPAN_MAX` e-folds; read while within `ZETA_SE_MAX`, 1%), seeds 1 / 2 / 3, the machine
shared with other jobs:

    rig             ring-down run decades  decay f              decay zeta        dwell f   dwell zeta  sweep f  one backbone f
    beam voltage    1.57 / 1.57 / 1.63     0.017 / 0.019 / 0.021  1.98 / 1.06 / 0.85  0.0009    0.88        0.0076   0.0073
    ministack base  1.79 / 1.77 / 1.68     0.039 / 0.039 / 0.033  1.73 / 1.35 / 2.28  0.0011    0.11        0.0021   0.050
    beam force      1.56 / 1.51 / 1.56     0.028 / 0.018 / 0.027  1.92 / 1.85 / 2.43  0.0032    0.39        0.0077   0.018

Every line met on all three rigs and seeds; the Ministack's seed-1 zeta 3.01% (a 5-period window at a 3.4-sigma
excursion of the noise) is gone: its windows there grow until their standard error is 0.5%. The forced decays
(beam force, through the force, `jointcal.measure.forced_decay`) keep their rule and their numbers.

Again 2026-11-26 (19:44 UTC, branch rd43: main 188c3e3 with rdcal merged, 817629e), seeds 1 / 2 / 3, the machine
shared with other jobs (load average 4-5), 2 min 14 s for the nine campaigns:

    rig             ring-down run decades  decay f                decay zeta          dwell f   dwell zeta  sweep f  one backbone f
    beam voltage    1.57 / 1.57 / 1.63     0.017 / 0.019 / 0.021  1.98 / 1.06 / 0.85  0.0009    0.88        0.0076   0.0073
    ministack base  1.79 / 1.77 / 1.68     0.039 / 0.039 / 0.033  1.73 / 1.35 / 2.28  0.0011    0.11        0.0021   0.050
    beam force      1.56 / 1.51 / 1.56     0.028 / 0.018 / 0.027  1.92 / 1.85 / 2.43  0.0032    0.39        0.0077   0.018

zeta2's numbers to every digit printed (the read-out is zeta2's; rdcal's calibration and held-out scores do not enter
here): every line met on all three rigs and seeds (the decades thinnest on the force rig's seed 2, 1.51; zeta's
worst 2.43%, the force rig's seed 3). The dwells' own decays read 1.5-2.2 decades. Calibration from ring-downs alone,
the posterior covering the truth (not in this benchmark): tests/calibrate/test_readouts.py::
test_ring_downs_alone_calibrate_and_the_posterior_covers_the_truth passed in the same branch's suite (460 passed, 1
xfailed).

(After the read-out's third-order refit, `jointcal.measure.ringdown._cubic_terms`; before it the Ministack read
decay f 0.099-0.103% and zeta 2.9-3.6%, the beam the same as now to 0.002% in f and 0.02% in zeta.)

- Beam, voltage reference: every line met.
- Ministack, base: NOT MET in seed 1, by a hair on zeta (3.01%; f now 0.039%, was 0.1004%); met in seeds 2 and 3
  (f 0.099%, 0.095%; zeta 2.44%, 2.50%). Seed 2's zeta had been 3.55% in its ring-down's last window (54
  periods, two e-folds): the window model's missing t^3 term of the log-envelope (+1.0 to +2.8% in zeta over
  two e-folds on a noise-free decay), which the refit takes out. What is left: f is worst in the 5 g ring-down's
  first window, 2.5 periods after the cut (-0.095 to -0.100%; -0.05% on a noise-free first-harmonic slow flow
  cut from the same amplitude: the band-pass continuation's junction with a decay whose frequency rises 1% a
  period). zeta's worst, seed 1's 3.01%, is a 5-period window in a 2 g dwell's decay (q 8.3e-6 in) whose
  standard error is 0.87%: a 3.4-sigma excursion of the noise; the read-out's rule (a window's standard error
  at most 1%) makes 3% a 3-sigma bound per window, over about 130 windows per seed here.
- Beam, force reference: every line met (the decades thinly: 1.51 in seed 2; seeds 4-6, same day: 1.56-1.86
  decades, decay f within 0.027%, zeta within 2.5%, dwells 0.0032% / 0.38%, one backbone 0.018%). After the voltage's cut the gauge
  goes on reading the armature's reaction and the decay rings at the coupled rig's pole, 2.4% below the
  structure's (``rd_vs_rig_pole_f_pct``: the read points against the rig's pole); each decay (flag
  ``through_force``) is read through the measured force (`jointcal.measure.forced_decay`: the structure's
  A / H(s) - s^2 = c' s + wn^2 at each window's s), with the modal constant of the lowest-level sweep's fit
  (0.24% low of 1/m, seed 1) and the second mode's receptance from that sweep's FRF flanks
  (`jointcal.measure.receptance`: 3.4% low): nothing of the truth. The decays' zeta holds a +0.5-0.6% mean
  bias (the joint's rate-independent loss read at the rig's frequency, 2.4% below the structure's). The
  open-loop dwells, one measured force level each (before: ``few_dwells``), are each read with the same A
  and R: f within 0.0032%, zeta within 0.39% of the structure at their amplitude (``dwell f``/``dwell
  zeta`` here: each dwell's own point, not a level's phase resonance). With zeta's standard error held at
  1% as the ring-down's (instead of 0.8%, `forced_decay.ZETA_SE_LIVE`) the ring-down runs read 1.69-1.81
  decades but one window in seed 3 read zeta 3.65% off.

Seeds 4 and 5 on main edd641e (2026-11-27 11:42, the machine otherwise idle), every rig; seed 4 / seed 5:

    rig             ring-down run decades  decay f          decay zeta    dwell f            dwell zeta     sweep f            one backbone f
    beam force      1.56 / 1.81            0.027 / 0.027    2.00 / 1.80   0.0030 / 0.0032    0.37 / 0.38    0.0078 / 0.0077    0.016 / 0.018
    beam voltage    1.73 / 1.57            0.021 / 0.025    1.96 / 2.98   0.0008 / 0.0008    0.87 / 0.88    0.0086 / 0.0083    0.0073 / 0.0070
    ministack base  1.75 / 1.68            0.035 / 0.038    1.21 / 1.53   0.0011 / 0.0005    0.094 / 0.088  0.0011 / 0.0018    0.052 / 0.050

Every line met; the beam's voltage seed 5 ring-down zeta, 2.98%, sits at the 3% line (the rule's 3-sigma bound
per window, above).
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).parents[2]
sys.path.insert(0, str(HERE))
from jointcal.models import harmonic_balance  # noqa: E402
from jointcal.synth import DEFAULT_SPEC, generate  # noqa: E402
from jointcal.synth.rig_truth import rig_pole  # noqa: E402
from jointcal.units import G  # noqa: E402
from tests._support import rigs  # noqa: E402
from tests._support.campaign import modal_tables  # noqa: E402

FIRST = DEFAULT_SPEC["assemblies"]["first"]
MINI = (FIRST["Fs"], FIRST["KT"], FIRST["chi"], FIRST["beta"], FIRST["k"], DEFAULT_SPEC["slug_weight_lbf"] / G,
        FIRST["zeta_v"])


def _ministack_spec(seed: int) -> tuple[dict, callable]:
    spec = {"seed": seed, "assemblies": {"first": FIRST},
            "series": [{"level_g": lev, "directions": ["up"]} for lev in (1.0, 2.0, 5.0)]
            + [{"level_g": 5.0, "test": "ringdown", "dwell_hz": [2180.0], "dwell_s": 0.3, "decay_s": 1.2},
               {"level_g": 2.0, "test": "dwell", "dwell_hz": [2140.0, 2160.0, 2180.0, 2200.0, 2220.0],
                "dwell_s": 0.4, "decay_s": 1.2}],
            "measurement": {"noise_fraction": 1e-3, "dc_offset_g": 0.0}}
    return spec, lambda q: harmonic_balance(np.asarray(q, float), *MINI)


NEAR = 1.5  # ring-down windows within this factor of a point's amplitude give the ring-downs' f there


def case(name: str, spec: dict, truth, folder: Path) -> dict:
    generate(spec, folder / "campaign", folder / "truth.json")
    modal = modal_tables(folder)
    table = pd.read_csv(modal / "modal_properties.csv", dtype={"flags": str})
    bb = pd.read_csv(modal / "backbone.csv")
    f_t, z_t = truth(bb["q_in"].to_numpy())
    bb = bb.assign(df=bb["f_hz"] / f_t - 1, dz=bb["zeta"] / z_t - 1)
    rd = bb[bb["test"] == "ringdown"]
    dec = rd.groupby("run_id")["q_in"].agg(lambda q: np.log10(q.max() / q.min()))
    own = set(table.loc[table["test"] == "ringdown", "run_id"])  # the ring-down runs (the others: dwells' decays)
    out = {"rig": name, "decays": int(dec.size), "rd_run_decades": float(dec[dec.index.isin(own)].min()),
           "dwell_decay_decades": f"{dec[~dec.index.isin(own)].min():.2g}-{dec[~dec.index.isin(own)].max():.2g}",
           "rd_f_max_pct": 100 * float(rd["df"].abs().max()), "rd_z_max_pct": 100 * float(rd["dz"].abs().max())}
    dw = table[table["test"] == "dwell"]
    out["dwell_flags"] = ";".join(sorted(set(";".join(dw["flags"].fillna("")).split(";")) - {""}))
    dw = (dw.dropna(subset=["q_dwell_quad_in"]).drop_duplicates("q_dwell_quad_in") if "q_dwell_quad_in" in dw
          else dw[:0])
    if len(dw):
        f_q, z_q = truth(dw["q_dwell_quad_in"].to_numpy())
        out["dwell_f_pct"] = 100 * float(np.abs(dw["f_dwell_quad_hz"].to_numpy() / f_q - 1).max())
        out["dwell_z_pct"] = 100 * float(np.abs(dw["zeta_dwell_quad"].to_numpy() / z_q - 1).max())
    sw = bb[bb["test"] == "sweep"]
    out["sweep_f_max_pct"] = 100 * float(sw["df"].abs().max()) if len(sw) else np.nan
    out["sweep_z_max_pct"] = 100 * float(sw["dz"].abs().max()) if len(sw) else np.nan
    # one backbone: each sweep's and each level's dwells' point against the ring-downs' windows at its amplitude
    worst = np.nan
    pts = pd.concat([sw[["q_in", "f_hz"]], pd.DataFrame({"q_in": dw["q_dwell_quad_in"], "f_hz": dw["f_dwell_quad_hz"]})
                     if len(dw) else sw[:0][["q_in", "f_hz"]]])
    for q, f in zip(pts["q_in"], pts["f_hz"]):
        near = rd[(rd["q_in"] > q / NEAR) & (rd["q_in"] < q * NEAR)]
        if len(near) >= 3:
            c = np.polyfit(np.log(near["q_in"]), near["f_hz"], 1)
            worst = np.nanmax([worst, abs(f / np.polyval(c, np.log(q)) - 1)])
    out["one_backbone_f_pct"] = 100 * worst
    out["decay_flags"] = ";".join(sorted(set(";".join(table.loc[table["test"] == "ringdown", "flags"].fillna(""))
                                             .split(";")) - {""}))
    if name == "beam force" and len(rd):  # read through the force: the structure's, 2.4% off the coupled rig's pole
        model, sh, second = rigs.rig()
        f_r = np.array([rig_pole(model, sh, v, second)[0] for v in rd["q_in"]])
        out["rd_vs_rig_pole_f_pct"] = 100 * float(np.abs(rd["f_hz"].to_numpy() / f_r - 1).max())
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--out", default=None)
    ap.add_argument("--rigs", default="beam force,beam voltage,ministack base")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in map(int, args.seeds.split(",")):
            for name, (spec, truth) in (("beam force", rigs.kinds_spec("force", seed)),
                                        ("beam voltage", rigs.kinds_spec("voltage", seed)),
                                        ("ministack base", _ministack_spec(seed))):
                if name not in args.rigs.split(","):
                    continue
                r = case(name, spec, truth, Path(tmp) / f"{name.replace(' ', '_')}_{seed}")
                r["seed"] = seed
                rows.append(r)
                print(json.dumps(r), flush=True)
    t = pd.DataFrame(rows)
    text = t.to_string(index=False, float_format=lambda v: f"{v:.3g}")
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
