"""sensor_gain: the response accelerometer's sensitivity is off by a factor the metadata do not hold."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, sensor_gain=v["gain"])


def _fingerprint(fp, sigma_db, sigma_f):
    g = fp.get("low_gain")
    gain_db = 20 * np.log10(g) if g else 0.0
    return abs(gain_db) > 3 * sigma_db, f"response/base far below resonance is {gain_db:+.2f} dB off the model"


def _advice(v):
    return (f"the response channel reads {abs(v['gain'] - 1) * 100:.0f}% {'high' if v['gain'] > 1 else 'low'}: check "
            "the response accelerometer's sensitivity (calibration sheet, the DAQ's mV/g setting) and repeat a "
            "low-level run")


EFFECT = Effect(
    "sensor_gain", (EffectParam("gain", "-", 0.5, 2.0, True, 1.0, "response channel reading / true acceleration"),),
    _apply, _advice, _fingerprint, hidden={"gain": 1.25},
    summary="response accelerometer sensitivity off (the channel reads gain x the true acceleration)",
    # one mode driven by a force or a voltage reads its modal constant A from the same response channel:
    # a gain g makes A g and q g, which the same joint with Fs g and KT, k per unit modal mass fits exactly
    kinds=("ministack",))
