"""The library of named physical effects a calibrated joint model may be missing.

Each effect is a model augmentation with one to three parameters (physical bounds and
units) living in `MinistackModel`, so the steady-state envelope model
(`jointcal.models.swept`), harmonic balance and the time simulation all see it.
An effect is one entry of `EFFECTS`: its parameters and a function
(baseline model, values, manifest row) -> augmented model. Adding an effect is adding
an entry here (and, if the structure lacks the physics, a field of `MinistackModel`).
Effects present together are named by joining them with `JOIN` ("a+b") and applied in
turn (`apply_effect`); their parameter names are distinct.

=====================  =============================================  =====================================
effect                 parameters                                     what it is
=====================  =============================================  =====================================
sensor_gain            gain (-)                                       response accelerometer sensitivity off
channel_delay          tau_s (s)                                      response channel lags the base channel
fixture_flexibility    f_can_hz (Hz), m_can_ratio (-)                 can/fixture on its own spring below
                                                                      the joint (zeta_can 1%)
cubic_stiffening       k3 (lbf/in^3)                                  k3 z^3 spring beside the joint
quadratic_damping      c2 (lbf s^2/in^2)                              c2 z'|z'| damper (air, foam)
joint_settling         Fs_drift (-), KT_drift (-), n_settle (runs)    Fs, KT rise with the run sequence n:
                                                                      X (1 + d (1 - exp(-(n-1)/n_settle)))
=====================  =============================================  =====================================
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np

from ..models import Fixture, IwanParams, MinistackModel

__all__ = ["EffectParam", "Effect", "EFFECTS", "apply_effect", "effects_of", "JOIN"]

N_SETTLE = 3.0  # start value of the settling time, runs


@dataclass(frozen=True)
class EffectParam:
    """One parameter of an effect: name, unit, bounds, scaling, start value and meaning."""

    name: str
    unit: str
    lo: float
    hi: float
    log: bool
    start: float
    meaning: str


@dataclass(frozen=True)
class Effect:
    """A named effect: its parameters, how it augments a model, what to check in the lab."""

    name: str
    params: tuple[EffectParam, ...]
    apply: Callable[[MinistackModel, Mapping[str, float], Mapping], MinistackModel]
    advice: Callable[[Mapping[str, float]], str]
    sequence_dependent: bool = False  # the model changes with the run's place in the test sequence


def _fixture(m: MinistackModel, v, row) -> MinistackModel:
    return replace(m, fixture=Fixture(m_can=v["m_can_ratio"] * m.m, f_can=v["f_can_hz"], zeta_can=0.01))


def _settling(m: MinistackModel, v, row) -> MinistackModel:
    s = 1.0 - np.exp(-(float(row.get("sequence", 1)) - 1.0) / v["n_settle"])
    iw = m.iwan
    return replace(m, iwan=IwanParams(iw.Fs * (1 + v["Fs_drift"] * s), iw.KT * (1 + v["KT_drift"] * s), iw.chi, iw.beta))


EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect("sensor_gain",
           (EffectParam("gain", "-", 0.5, 2.0, True, 1.0, "response channel reading / true acceleration"),),
           lambda m, v, row: replace(m, sensor_gain=v["gain"]),
           lambda v: (f"the response channel reads {abs(v['gain'] - 1) * 100:.0f}% "
                      f"{'high' if v['gain'] > 1 else 'low'}: check the response accelerometer's sensitivity "
                      "(calibration sheet, the DAQ's mV/g setting) and repeat a low-level run")),
    Effect("channel_delay",
           (EffectParam("tau_s", "s", 0.0, 5e-4, False, 2e-5, "response channel delay relative to the base"),),
           lambda m, v, row: replace(m, sensor_delay_s=v["tau_s"]),
           lambda v: (f"the response channel lags the base channel by {v['tau_s'] * 1e6:.0f} us: check the "
                      "anti-alias filters and signal conditioners of the two channels (same type and setting), "
                      "or correct the phase by 2 pi f tau")),
    Effect("fixture_flexibility",
           (EffectParam("f_can_hz", "Hz", 1000.0, 30000.0, True, 6000.0, "own frequency of the can on its spring"),
            EffectParam("m_can_ratio", "-", 0.3, 50.0, True, 4.0, "moving can mass over slug mass")),
           _fixture,
           lambda v: (f"the fixture below the joint is flexible (a mode near {v['f_can_hz']:.0f} Hz with "
                      f"{v['m_can_ratio']:.1f}x the slug's mass): the control accelerometer does not see the motion "
                      "under the joint; stiffen the fixture or control on an accelerometer at the joint's base, "
                      "and keep the fixture DOF in the model")),
    Effect("cubic_stiffening",
           (EffectParam("k3", "lbf/in^3", -5e13, 5e13, False, 0.0, "cubic spring beside the joint"),),
           lambda m, v, row: replace(m, k3=v["k3"]),
           lambda v: (f"a cubic spring k3 = {v['k3']:.3g} lbf/in^3 acts beside the joint "
                      f"({'stiffening' if v['k3'] > 0 else 'softening'} with amplitude): look for a preload-dependent "
                      "contact (foam compression, a stop); expect odd harmonics")),
    Effect("quadratic_damping",
           (EffectParam("c2", "lbf s^2/in^2", 0.0, 200.0, False, 0.5, "quadratic (velocity-squared) damper"),),
           lambda m, v, row: replace(m, c2=v["c2"]),
           lambda v: (f"damping grows with velocity as c2 z'|z'| (c2 = {v['c2']:.3g} lbf s^2/in^2), which no Iwan "
                      "(Masing) joint gives: look for air pumping through vents or foam cells; add the damper")),
    Effect("joint_settling",
           (EffectParam("Fs_drift", "-", -0.5, 1.0, False, 0.05, "relative rise of Fs over the run sequence"),
            EffectParam("KT_drift", "-", -0.5, 1.0, False, 0.05, "relative rise of KT over the run sequence"),
            EffectParam("n_settle", "runs", 0.5, 20.0, True, N_SETTLE, "runs over which the joint settles (1/e)")),
           _settling,
           lambda v: (f"the joint settled during the test (Fs {v['Fs_drift'] * 100:+.0f}%, KT {v['KT_drift'] * 100:+.0f}% "
                      f"over about {v['n_settle']:.1f} runs): run low-level sweeps until they repeat before the test "
                      "series, or calibrate on the settled runs only"),
           sequence_dependent=True),
)}


JOIN = "+"  # effects present together: "fixture_flexibility+quadratic_damping"


def effects_of(name: str) -> tuple[str, ...]:
    """The library effects of a model name: () for 'baseline', one or more joined by `JOIN`."""
    if name == "baseline":
        return ()
    parts = tuple(name.split(JOIN))
    bad = [p for p in parts if p not in EFFECTS]
    if bad or len(set(parts)) != len(parts):
        raise ValueError(f"unknown effect(s) {', '.join(bad) or name!r}; the library has {', '.join(EFFECTS)} "
                         f"(join distinct effects with {JOIN!r}).")
    return parts


def apply_effect(model: MinistackModel, name: str, values: Mapping[str, float], row: Mapping) -> MinistackModel:
    """The model with effect(s) `name` at `values` for the run of manifest `row` ('baseline': unchanged).

    Joined effects ("a+b") are applied in turn; each reads its own parameters from `values`
    (parameter names are distinct across the library)."""
    for e in effects_of(name):
        model = EFFECTS[e].apply(model, values, row)
    return model
