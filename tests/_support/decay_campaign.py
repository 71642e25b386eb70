"""Test helpers (not jointcal code): a virtual campaign of ring-downs of the jointed beam, measured, calibrated and
diagnosed by the discrepancy stage.

The rig is `tests/_support/rigs.py`'s jointed beam on its small open-loop shaker, voltage-driven (a force gauge
keeps reading the armature after the cut, so a force-referenced record shows no cut-off to the read-out): each
ring-down is a dwell at the mode's frequency (at 3e-3 in) held for `DWELL_S`, cut to zero, and `DECAY_S` of free
decay; one ring-down per amplifier level of `levels_V` (steady amplitudes 1e-3, 3e-3 and 8e-3 in at resonance).
The exact Iwan time simulation (`jointcal.synth.generate`) with the hidden effect, the DAQ chain with its noise;
the modal stage's read-out (`campaign_modal`: ring-down windows into backbone.csv); the calibration from the
ring-downs alone (GA on eq. 3.9, the modal kind); then `jointcal.discrepancy.diagnose` with the backbone table.
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from jointcal.calibrate import CalibrateSettings, run_calibration
from jointcal.calibrate.ga import GAOptions
from jointcal.discrepancy import DiscrepancySettings, diagnose
from jointcal.discrepancy.stage import valley_starts
from jointcal.io import read_manifest, read_run
from jointcal.synth import generate
from tests._support.campaign import modal_tables
from tests._support.rigs import JOINTED_BEAM, SMALL_SHAKER, levels_V, truth_curve

DWELL_S, DECAY_S = 1.5, 1.5  # s: the dwell reaches its steady state (zeta ~1.5%: 1/(zeta w) 0.11 s)
NOISE = 0.005  # of each channel's RMS: at 2% the drive's noise after the cut stays above the read-out's 2% "off"


def ring_down_campaign(folder: Path, effect: str = "none", params: dict | None = None, *, seed: int = 1,
                       noise: float = NOISE, levels: list[float] | None = None, also: dict | None = None) -> Path:
    """Generate and read the campaign into folder/campaign and folder/modal; returns folder/modal. also : a
    second hidden effect ({name, params})."""
    f, _ = truth_curve("voltage", 3e-3)
    series = [{"level_V": v, "test": "ringdown", "dwell_hz": [round(f, 1)], "dwell_s": DWELL_S, "decay_s": DECAY_S}
              for v in (levels or levels_V())]
    spec = {"seed": seed, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": noise},
            "sweep": {"f_start_hz": 0.7 * f, "f_stop_hz": 1.3 * f, "rate_hz_per_s": 1.0, "ramp_s": 0.05,
                      "tail_s": 1.5},  # no sweep is run: the spec's sweep section is required
            "series": series, "assemblies": {"beam": JOINTED_BEAM},
            "effect": {"name": effect, "params": params or {}, **({"also": also} if also else {})},
            "rig": {"reference": "voltage", "shaker": SMALL_SHAKER}}
    generate(spec, folder / "campaign", folder / "truth.json")
    return modal_tables(folder)


def ministack_ring_downs(folder: Path, effect: str = "none", params: dict | None = None, *, seed: int = 5,
                        levels: tuple = (0.3, 1.0, 3.0, 10.0)) -> Path:
    """The base-driven Ministack's first assembly (Table 3.2) rung down from a dwell at each level's resonance (g),
    as tests/calibrate/test_readouts.py makes them (0.1% noise, no DC offset), the effect hidden; folder/modal."""
    from jointcal.models import resonance_amplitude
    from jointcal.synth import DEFAULT_SPEC
    from jointcal.units import G

    first = DEFAULT_SPEC["assemblies"]["first"]
    m = DEFAULT_SPEC["slug_weight_lbf"] / G
    series = []
    for lv in levels:
        f = float(resonance_amplitude(lv, *(first[p] for p in ("Fs", "KT", "chi", "beta", "k")), m,
                                      first["zeta_v"])[1])
        series.append({"level_g": lv, "test": "ringdown", "dwell_hz": [round(f, 1)], "dwell_s": 0.2, "decay_s": 1.2})
    spec = {**DEFAULT_SPEC, "seed": seed, "assemblies": {"first": first}, "series": series,
            "measurement": {**DEFAULT_SPEC["measurement"], "noise_fraction": 1e-3, "dc_offset_g": 0.0},
            "effect": {"name": effect, "params": params or {}}}
    generate(spec, folder / "campaign", folder / "truth.json")
    return modal_tables(folder)


def calibrate_and_diagnose(folder: Path, settings: DiscrepancySettings, *, ga: GAOptions | None = None,
                           log=None, assembly: str = "beam") -> dict:
    """Calibrate from the ring-downs (the model kind following the excitation; `ga` the GA's options) and
    diagnose; the diagnosis."""
    modal = folder / "modal"
    cal = CalibrateSettings(model_kind="auto", **({"ga": ga} if ga is not None else {}))
    run_calibration(modal / "modal_properties.csv", assembly, folder / "cal", cal, backbone_csv=modal / "backbone.csv")
    best = json.loads((folder / "cal" / "ga_best.json").read_text())
    rows = read_manifest(folder / "campaign" / "manifest.csv").to_dict("records")
    records = [read_run(folder / "campaign" / r["file"], r) for r in rows]
    return diagnose(assembly, {}, pd.read_csv(modal / "modal_properties.csv"), best, None, records, rows,
                    space=cal.resolved(best).space, settings=settings, backbone=pd.read_csv(modal / "backbone.csv"),
                    joint_starts=valley_starts(pd.read_csv(folder / "cal" / "ga_history.csv"), best), log=log)
