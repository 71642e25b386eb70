"""fixture_flexibility: the can under the joint moves on its own spring, between the control accelerometer and the joint.

The can (mass m_can_ratio x the slug's, own frequency f_can_hz with the slug removed) is an
extra DOF driven by the base and loaded by the slug (`jointcal.models.structure`). Its
damping ratio is fixed at `ZETA_CAN` (1%), in the virtual lab and in the fit alike: the can's
mode lies above the tested band (5-6 kHz against ~2 kHz), where its damping barely changes
the slug's response, so the data cannot fix it and a free zeta_can would only widen the fit.
"""
from __future__ import annotations

from dataclasses import replace

from ..models import Fixture
from .effect import Effect, EffectParam

__all__ = ["EFFECT", "ZETA_CAN"]

ZETA_CAN = 0.01


def _apply(model, v, row):
    return replace(model, fixture=Fixture(m_can=v["m_can_ratio"] * model.m, f_can=v["f_can_hz"], zeta_can=ZETA_CAN))


def _fingerprint(fp, sigma_db, sigma_f):
    tr = fp.get("low_gain_trend") or 0.0
    return tr > 0.02, f"the low-frequency gain error rises with (f/f_res)^2 (slope {tr:.3f})"


def _advice(v):
    return (f"the fixture below the joint is flexible (a mode near {v['f_can_hz']:.0f} Hz with {v['m_can_ratio']:.1f}x "
            "the slug's mass): the control accelerometer does not see the motion under the joint; stiffen the "
            "fixture or control on an accelerometer at the joint's base, and keep the fixture DOF in the model")


EFFECT = Effect(
    "fixture_flexibility",
    (EffectParam("f_can_hz", "Hz", 1000.0, 30000.0, True, 6000.0, "own frequency of the can on its spring"),
     EffectParam("m_can_ratio", "-", 0.3, 50.0, True, 4.0, "moving can mass over slug mass")),
    _apply, _advice, _fingerprint, hidden={"f_can_hz": 5500.0, "m_can_ratio": 4.0},
    summary="can/fixture on its own spring below the joint (zeta_can fixed at 1%): slug mode ~2-3% lower",
    kinds=("ministack",))  # the Ministack's can; one mode of another structure has its neighbour_mode
