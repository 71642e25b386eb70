"""Acceptance of the discrepancy stage from ring-downs (issue 31: "the discrepancy stage names a hidden effect from
ring-downs").

Each case: a virtual campaign of three ring-downs of the voltage-driven jointed beam (`tests/_support/decay_campaign.py`:
dwells at the mode reaching 1e-3, 3e-3 and 8e-3 in, cut off, 1.5 s of free decay; the exact Iwan time simulation
with the hidden effect; 0.5% noise), read by the modal stage, calibrated from the ring-downs alone with the
workflow's default config, then `jointcal.discrepancy.diagnose` (the decay path: backbone points, held-out runs,
the rule, GA + posterior recalibration, revalidation by the decays' time simulation). Prints per case: the effect
named, confidence, the time-domain E before and after, the backbone's floor, the named effect's parameter against
the truth's (per unit modal mass of the rig's mode, beam and armature, for k3), the stage's time.

    python tests/benchmarks/accept_discrepancy_decays.py [--rig beam|ministack] [--seeds 1,2,3] [--only NAME]
        [--out FILE]

A channel delay is hidden too: a free decay cannot show it, so 'none' is the right answer from ring-downs (the
stage does not try it and says so).

Measured 2026-11-26 (loaded 2-core machine), see the table at the end of this docstring once run.
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).parents[2]))
from tests._support.decay_campaign import calibrate_and_diagnose, ministack_ring_downs, ring_down_campaign  # noqa: E402

from jointcal.discrepancy import DiscrepancySettings  # noqa: E402

CONFIG = yaml.safe_load((Path(__file__).parents[2] / "workflow" / "config" / "config.yaml").read_text())
M_RIG = 1.05 / 386.089  # the rig's mode: the 1 lbf beam and the 0.05 lbf armature
CASES = [
    ("none", {}, "none"),
    ("cubic_stiffening", {"k3": 1e6}, "cubic_stiffening"),
    ("elastic_softening", {"loss_ratio": 0.3}, "elastic_softening"),
    ("joint_settling", {"Fs_drift": 0.15, "KT_drift": 0.1}, "joint_settling"),
    ("channel_delay", {"tau_s": 4e-4}, "none"),  # what a decay shows of it: nothing
    ("elastic_softening", {"loss_ratio": 0.3, "also": {"name": "cubic_stiffening", "params": {"k3": 1e6}}},
     "elastic_softening+cubic_stiffening"),
]


MINISTACK = [  # the base-driven Ministack (first assembly, four ring-downs 0.3-10 g, 0.1% noise), hidden strengths
    ("none", {}, "none"),  # the library's defaults
    ("cubic_stiffening", {"k3": 5e11}, "cubic_stiffening"),
    ("cubic_stiffening", {"k3": 2e12}, "cubic_stiffening"),
    ("quadratic_damping", {}, "quadratic_damping"),
    ("channel_delay", {"tau_s": 4e-5}, "none"),
]


def _truth_value(name: str, value: float, rig: str) -> float:
    return value / M_RIG if name == "k3" and rig == "beam" else value


def run_case(effect: str, params: dict, seed: int, rig: str = "beam") -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        p = {k: v for k, v in params.items() if k != "also"}
        t0 = time.perf_counter()
        if rig == "beam":
            ring_down_campaign(folder, effect, p, seed=seed, also=params.get("also"))
        else:
            ministack_ring_downs(folder, effect, p or None, seed=seed)
        t1 = time.perf_counter()
        d = calibrate_and_diagnose(folder, DiscrepancySettings.from_config(CONFIG["discrepancy"]),
                                   assembly="beam" if rig == "beam" else "first")["diagnosis"]
        t2 = time.perf_counter()
    eff = d["recalibrated"]["effect_parameters"]
    truth = {**p, **(params.get("also", {}).get("params", {}))}
    got = "; ".join(f"{k} {v['value']:.3g} (truth {_truth_value(k, truth[k], rig):.3g})" if k in truth else
                    f"{k} {v['value']:.3g}" for k, v in eff.items())
    return dict(effect=d["effect"], confidence=d["confidence"], E_before=d["metric_before"], E_after=d["metric_after"],
                floor=d["fast_model_floor"]["E"], params=got, stage_s=t2 - t1, total_s=t2 - t0,
                not_seen=",".join(d["not_seen_by_decays"]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--only", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--rig", default="beam", choices=("beam", "ministack"))
    a = ap.parse_args(argv)
    lines = []
    for effect, params, want in (CASES if a.rig == "beam" else MINISTACK):
        label = want if effect != "channel_delay" else "channel_delay"
        if a.only and a.only not in (effect, label):
            continue
        for seed in [int(s) for s in a.seeds.split(",")]:
            r = run_case(effect, params, seed, a.rig)
            ok = "ok" if r["effect"] == want else "MISS"
            change = r["E_after"] / r["E_before"] - 1
            line = (f"{label:36s} seed {seed}: {r['effect']:36s} {r['confidence']:6s} E {r['E_before']:6.2f} -> "
                    f"{r['E_after']:5.2f} ({change:+5.0%})  floor {r['floor']:.2f}  {ok:4s} {r['params']}  "
                    f"stage {r['stage_s']:.0f} s")
            print(line, flush=True)
            lines.append(line)
            if a.out:
                Path(a.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
