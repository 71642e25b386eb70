"""A virtual shaker lab: campaigns in the raw-data contract from a known truth.

`generate(spec, out_dir, truth_path)` simulates every run of the spec's test series
(sweeps; dwells and ring-downs, `jointcal.synth.dwell` and `jointcal.synth.ringdown`) with the exact-Iwan simulator
(plus the hidden effect, if any), passes both channels through the measurement chain
(`jointcal.synth.daq`), and writes the campaign (manifest + one file per run) and, separately, the truth: parameters, effect
and per run the harmonic-balance steady-state resonance at that level.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from dataclasses import replace

from ..effects import EFFECTS
from ..io import write_csv_atomic, write_json_atomic, write_run
from ..io.testkinds import DEFAULT, TEST_KINDS, is_swept
from ..models import resonance_amplitude, simulate
from ..units import G
from . import daq, dwell, ringdown
from .hidden import effect_defaults, run_model
from .non_masing import KEY, share_of, with_share
from .rig_truth import rig_truth
from .shaker import Shaker, StructureMode, simulate_rig
from .spec import JOINT_KEYS, RIG_LEVEL, load_spec

__all__ = ["generate", "plan_runs"]

PLANS = {"dwell": dwell.plan, "ringdown": ringdown.plan}  # a test kind's series item -> its manifest rows
_RANGES_G = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000)


def plan_runs(spec: dict) -> pd.DataFrame:
    """The manifest rows of a spec's test series, before any simulation.

    A force-driven rig's rows carry the amplifier's level_V and a NaN level_lbf: the
    force the gauge measures is known after the simulation (`generate` fills it in and
    drops level_V from the manifest).
    """
    rows = []
    sw = spec["sweep"]
    lo, hi = sorted((sw["f_start_hz"], sw["f_stop_hz"]))
    ref = spec.get("rig", {}).get("reference", "base")
    key = RIG_LEVEL[ref]
    unit = key.split("_")[1]
    for assembly in spec["assemblies"]:
        seq = int(spec.get("first_sequence", 1)) - 1  # a campaign generated in parts continues its sequence
        for item in spec["series"]:
            test = item.get("test", DEFAULT)
            if test not in TEST_KINDS or not TEST_KINDS[test].swept:  # dwells or ring-downs: a run per frequency
                if test not in PLANS:
                    raise ValueError(f"series item {item}: test must be {DEFAULT} or one of {', '.join(PLANS)}.")
                seq = PLANS[item["test"]](rows, item, assembly, seq, ref, float(spec["sample_rate_hz"]),
                                          spec["file_format"])
                continue
            for _ in range(item.get("repeats", 1)):
                for direction in item.get("directions", ["up", "down"]):
                    seq += 1
                    f0, f1 = (lo, hi) if direction == "up" else (hi, lo)
                    run_id = f"{assembly}_{seq:02d}_{item[key]:g}{unit}_{direction}"
                    level = {key: float(item[key])} if ref != "force" else {"level_V": float(item[key]),
                                                                            "level_lbf": np.nan}
                    rows.append(dict(run_id=run_id, assembly=assembly, sequence=seq, **level,
                                     direction=direction, f_start_hz=f0, f_stop_hz=f1,
                                     sweep_rate_hz_per_s=float(sw["rate_hz_per_s"]),
                                     sample_rate_hz=float(spec["sample_rate_hz"]),
                                     file=f"runs/{run_id}.{spec['file_format']}"))
    plan = pd.DataFrame(rows)
    if "test" in plan:  # a campaign with dwells or ring-downs: the sweeps say so too
        plan["test"] = plan["test"].fillna(DEFAULT)
    return plan


def _full_scale(setting: Any, peak: float) -> float:
    """A channel's ADC range: a number (g), or 'auto' = smallest standard range >= 2x the peak."""
    if setting == "auto":
        return float(next((r for r in _RANGES_G if r >= 2.0 * peak), _RANGES_G[-1]))
    return float(setting)


def _truth_row(truth: dict, model, level: float) -> dict:
    iw = model.iwan
    if iw is None:  # linear structure: phase resonance m a = c w q
        w = np.sqrt(model.k / model.m)
        q = level * G / (2 * model.zeta_v * w**2)
        return dict(Fs=np.nan, KT=np.nan, q_hb_in=float(q), f_hb_hz=float(w / (2 * np.pi)), zeta_hb=model.zeta_v)
    q, f, z = resonance_amplitude(level, iw.Fs, iw.KT, iw.chi, iw.beta, model.k, model.m, model.zeta_v)
    return dict(Fs=iw.Fs, KT=iw.KT, q_hb_in=float(q), f_hb_hz=float(f), zeta_hb=float(z))


_PLACEHOLDER_JOINT = {"Fs": 1.0, "KT": 1.0, "chi": -0.5, "beta": 0.1}


def _model(truth: dict, sequence: int, effect: str, eparams: dict, also: dict | None = None):
    """The run's model: `run_model`, or its linear version for an assembly without a joint; with
    `also` ({name, params}) the second effect is applied to the first's model; with ``backbone_share``
    s, s of the joint's force is elastic along its backbone (`jointcal.synth.non_masing`)."""
    joint = all(k in truth for k in JOINT_KEYS)
    t = truth if joint else {**truth, **_PLACEHOLDER_JOINT}
    model = run_model(t, sequence, effect, eparams)
    if also and also["name"] != "none":
        model = EFFECTS[also["name"]].apply(model, effect_defaults(also["name"], also.get("params")),
                                            {"sequence": sequence})
    return with_share(model, float(truth.get(KEY, 0.0))) if joint else replace(model, iwan=None)


def generate(spec: dict | str | os.PathLike, out_dir: str | os.PathLike, truth_path: str | os.PathLike) -> pd.DataFrame:
    """Write a campaign and its truth; return the truth table (one row per run).

    Parameters
    ----------
    spec : dict or path
        Truth spec (YAML/JSON); see `jointcal.synth.spec` for the keys.
    out_dir : path
        Campaign folder to create (manifest.csv and runs/).
    truth_path : path
        Where to write the truth JSON; must lie outside `out_dir`.
    """
    spec = load_spec(spec)
    out_dir = Path(out_dir).resolve()
    truth_path = Path(truth_path).resolve()
    if out_dir == truth_path.parent or out_dir in truth_path.parents:
        raise ValueError(f"{truth_path}: the truth file must not live inside the campaign folder {out_dir}; "
                         "write it elsewhere (e.g. under tests/).")
    rng = np.random.default_rng(spec["seed"])
    meas = spec["measurement"]
    fs_out = float(spec["sample_rate_hz"])
    fs_sim = fs_out * int(meas["oversample"])
    sos = daq.antialias(fs_sim, fs_out, meas["antialias_order"], meas["antialias_cutoff"])
    effect = spec["effect"]["name"]
    eparams = effect_defaults(effect, spec["effect"].get("params"))
    sw = spec["sweep"]
    ref = spec["rig"]["reference"]
    shaker = Shaker(**spec["rig"]["shaker"])
    second = spec["rig"].get("second_mode")
    second = None if second is None else StructureMode(**{k: float(v) for k, v in second.items()})
    plan = plan_runs(spec)
    masses = {a: v.get("weight_lbf", spec["slug_weight_lbf"]) / G for a, v in spec["assemblies"].items()}
    truth_rows = []
    for i, row in enumerate(plan.itertuples(index=False)):
        run_rng = np.random.default_rng([spec["seed"], int(rng.integers(2**31))])
        truth = {k: v for k, v in spec["assemblies"][row.assembly].items() if k != "weight_lbf"}
        truth["m"] = masses[row.assembly]
        model = _model(truth, row.sequence, effect, eparams, spec["effect"].get("also"))
        level = row.level_g if ref == "base" else row.level_V
        # base: the controller holds the base acceleration (ripple); a rig's amplifier is open loop
        swept = is_swept(getattr(row, "test", DEFAULT))
        f0, f1, rate, tail = ((row.f_start_hz, row.f_stop_hz, row.sweep_rate_hz_per_s, sw["tail_s"])
                              if swept else dwell.drive_band(row))
        # a dwell's drive is cut off, not ramped down: its ring-down starts from the steady state
        t, f_inst, drive = daq.controlled_sweep(fs_sim, f0, f1, rate, level, rng=run_rng,
                                                ramp_s=sw["ramp_s"] if swept else 0.0,
                                                tail_s=tail, ripple=meas["ripple"] if ref == "base" else 0.0,
                                                distortion=tuple(meas["distortion"]))
        if ref == "base" and share_of(model) > 0:
            raise ValueError(f"assembly {row.assembly!r}: {KEY} needs rig reference force or voltage (the base "
                             "rig's truth rows are the Iwan joint's harmonic balance); set rig.reference.")
        if ref == "base":
            reference, resp = drive, simulate(model, drive, fs_sim, omega_h=0.3).response_g  # truth finer than any estimator
            extra = _truth_row(truth, model, row.level_g)
        else:
            resp, force, x = simulate_rig(model, shaker, drive, fs_sim, omega_h=0.3, second=second)
            reference = force if ref == "force" else drive
            extra = rig_truth(model, shaker, level, t, f_inst, x, second=second)
            extra = dict(Fs=truth.get("Fs", np.nan), KT=truth.get("KT", np.nan), level_V=level, **extra)
            if ref == "force":  # the manifest's level: the force amplitude the gauge saw over the sweep
                on = np.abs(drive) > 0
                level_lbf = float(np.sqrt(2 * np.mean(force[on] ** 2)))
                plan.loc[i, "level_lbf"] = extra["level_lbf"] = round(level_lbf, 6)
        chans, ranges = [], {}
        for name, x in (("base", reference), ("response", resp)):
            fsg = ranges[f"full_scale_{name}_g"] = _full_scale(meas["full_scale_g"][name], float(np.max(np.abs(x))))
            off = ranges[f"dc_offset_{name}_g"] = float(meas["dc_offset_g"] * run_rng.standard_normal())
            chans.append(daq.measure(x, fs_sim, fs_out, rng=run_rng, noise_fraction=meas["noise_fraction"],
                                     dc_offset=off, full_scale_g=fsg, bits=meas["bits"], sos=sos))
        write_run(out_dir / row.file, t[:: int(meas["oversample"])], chans[0], chans[1], kind=ref)
        lev = {"level_g": row.level_g} if ref == "base" else {}
        truth_rows.append(dict(run_id=row.run_id, assembly=row.assembly, sequence=row.sequence,
                               **lev, direction=row.direction, **ranges, **extra))
    manifest = plan.drop(columns=[c for c in dwell.PRIVATE if c in plan])
    if "dwell_hz" in manifest and manifest["dwell_hz"].isna().all():  # ring-downs only: no empty last column
        manifest = manifest.drop(columns=["dwell_hz"])
    write_csv_atomic(manifest.drop(columns=["level_V"]) if ref == "force" else manifest, out_dir / "manifest.csv")
    table = pd.DataFrame(truth_rows)
    write_json_atomic(dict(spec=spec, effect=dict(name=effect, params=eparams),
                           assemblies={a: dict(v, m=masses[a]) for a, v in spec["assemblies"].items()},
                           runs=table.to_dict(orient="records")), truth_path)
    return table
