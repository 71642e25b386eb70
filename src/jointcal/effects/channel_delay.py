"""channel_delay: the response channel lags the reference channel (base, force or drive voltage: filters, conditioners)."""
from __future__ import annotations

from dataclasses import replace

from .effect import Effect, EffectParam

__all__ = ["EFFECT"]


def _apply(model, v, row):
    return replace(model, sensor_delay_s=v["tau_s"])


def _fingerprint(fp, sigma_db, sigma_f):
    dl = fp.get("delay_us") or 0.0
    return abs(dl) > 3.0, f"the phase error grows as 2 pi f tau with tau = {dl:.1f} us"


def _advice(v):
    return (f"the response channel lags the reference channel by {v['tau_s'] * 1e6:.0f} us: check the anti-alias filters "
            "and signal conditioners of the two channels (same type and setting), or correct the phase by 2 pi f tau")


def _rescale(sc):
    """0 to a fifth of the stuck period, 72 deg at f0 (the Ministack's 0-500 us is about a fifth at 400 Hz)."""
    return {"tau_s": (0.0, 0.2 / sc["f0"], 0.01 / sc["f0"])}


EFFECT = Effect(
    "channel_delay", (EffectParam("tau_s", "s", 0.0, 5e-4, False, 2e-5, "response channel delay relative to the reference"),),
    _apply, _advice, _fingerprint, hidden={"tau_s": 40e-6},
    summary="response channel delayed by tau_s relative to the reference channel (exact fractional delay)",
    rescale=_rescale)
