"""The drive path of a voltage-driven campaign, its slope refit on the envelope frames the stage judges.

An amplifier voltage drives the mode through the shaker's coil: the read-out
(`jointcal.measure.sweepfit`) takes that path as a complex modal constant linear in w,
A(w) = A_c + A' (w - w_c) (`jointcal.validate.drive.drive_gain`: the campaign's median), fitted
over the response's passage through resonance, where the slope is barely seen and a ridge
holds it near zero. The discrepancy fits judge a wider band (`DiscrepancySettings.band`),
whose far frames carry the smallest repeat scatter: there the coil's phase, -atan(w L / R),
keeps turning, and the part of its slope the read-out left out shows as a phase misfit
linear in w that no joint model and no effect of the library follows. It is the same in
every candidate, so it raises every held-out score alike and hides the effect that differs
(on the jointed beam's rig: a phase slope a tenth of the coil's, 2.6 deg across +-30% of
the mode, E 1.6 for a campaign that hides nothing).

So before the candidates are scored, A' is refit with the baseline on those frames, A_c kept
(the read-out's resonance fixes it): in turns, the baseline's joint parameters by `Objective.fit`
and the slope's real and imaginary parts by linear least squares of the weighted residuals
(dB, deg) on log A(w) (`refine_slope`). Every candidate, the recalibration and the time-domain
revalidation then take the refined A(w); the fast model's floor is taken before, with the
read-out's, as the validation's simulation was driven. A baseline that misses (an effect hidden)
moves the slope it finds (on the jointed beam with elastic softening: -0.061i against the rig's
-0.090i, relative; cubic stiffening hidden: +0.030-0.140i, and the cubic's held-out score 2.8).
So when a candidate scores better than the baseline, the slope is refit with it and the library
scored again; and a named model refits it once more, from its own fit, before its recalibration
(elastic softening: -0.090i, and the loss ratio 0.37 -> 0.31, truth 0.30). `refine_slope` takes
any candidate. A refit slope past any coil's (|A' w_c / A_c| > `MAX_RELATIVE_SLOPE`) is not the drive's:
the baseline has bent the drive to an effect it misses (on the jointed beam with a neighbouring mode hidden,
-6.6 + 1.3i, and the neighbour then scored 15 where the read-out's drive leaves it the best), so the read-out's
drive is kept and the slope reported as rejected.

The slope is refit only where the fast model is within the repeat scatter of its own time simulation
(`refits_slope`: the floor E at most `rule.FLOOR_HIGH`); above it, the fast model that would judge the
slope is further from its record than the slope moves it (the real UNESP beam: floor 30).

A force at the driving point is 1/m by physics (real, no slope): its drive is |A| as the read-out gives it
(`validate.drive.drive_gain`); a phase the read-out's A took (`jointcal.measure.sweepfit`: a response channel
lagging the force) is the channels', left in the data for the library's channel_delay to find.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from .data import RunEnvelope
from .fit import Candidate, Fit, Objective
from .rule import FLOOR_HIGH

__all__ = ["ROUNDS", "MAX_RELATIVE_SLOPE", "refits_slope", "refine_slope"]

ROUNDS = 4  # turns of (joint fit, slope) at most; they stop earlier once the slope moves < 2% of itself
MAX_RELATIVE_SLOPE = 1.0  # |A' w_c / A_c| of a coil's 1 / (1 + i w tau) is x / sqrt(1 + x^2) < 1, x = w_c tau
Gain = tuple[complex, complex, float]


def refits_slope(level_unit: str, floor: float | None) -> bool:
    """Whether the stage refits the drive's slope (`refine_slope`): a voltage drive (level unit 'V') whose fast
    model's floor E (None: not measured, taken as 0) is at most `rule.FLOOR_HIGH`, the repeat scatter."""
    return level_unit == "V" and (floor is None or floor <= FLOOR_HIGH)


def _slope_step(obj: Objective, theta: NDArray, gain: Gain) -> complex:
    """The change of A' (per rad/s) that best takes out the residuals of `obj` at theta, linearised:
    log(A + d u) - log A = d u / A, u = w - w_c (clipped as `gain_at` clips it)."""
    ac, da, wc = gain
    rows, rhs = [], []
    k = 20.0 / np.log(10.0)
    for i, run in enumerate(obj.runs):
        with np.errstate(all="ignore"):
            d = obj.predict(theta, i) / run.T
        u = np.clip(2 * np.pi * run.f_hz - wc, -0.45 * wc, 0.45 * wc)
        x = u / (ac + da * u)
        w = 1.0 / np.sqrt(2.0 * run.f_hz.size * len(obj.runs))  # as the objective weights each run
        ok = np.isfinite(d) & (np.abs(d) > 0)
        # d = a + i b: dB change k Re(d x) = k (a Re x - b Im x); deg change deg Im(d x) = deg (a Im x + b Re x)
        rows.append((np.c_[k * x.real, -k * x.imag] / run.sigma_db[:, None] * w)[ok])
        rhs.append((-20 * np.log10(np.abs(d)) / run.sigma_db * w)[ok])
        rows.append((np.degrees(np.c_[x.imag, x.real]) / run.sigma_deg[:, None] * w)[ok])
        rhs.append((-np.degrees(np.angle(d)) / run.sigma_deg * w)[ok])
    a, b = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    return complex(a, b)


def refine_slope(c0: Candidate, theta0: NDArray, gain: Gain, build: Callable[[Gain], Sequence[RunEnvelope]], *,
                 max_nfev: int, rounds: int = ROUNDS) -> tuple[Gain, list[RunEnvelope], dict]:
    """The campaign's drive A(w) with its slope refit with the baseline on the envelope frames.

    Parameters
    ----------
    c0 : Candidate
        The model refit with the slope (the baseline, or the model named).
    theta0 : ndarray, shape (6,) or (n,)
        The first fit's start (the calibration's joint parameters, or the named model's fit).
    gain : (A_c, A' per rad/s, w_c rad/s)
        The read-out's modal constant (`drive_gain`).
    build : callable gain -> runs
        The assembly's `RunEnvelope`s with that drive.
    max_nfev : int
        Each baseline fit's effort.

    Returns
    -------
    gain, runs, info
        The refined gain, the runs with it, and for diagnosis.json: the slope before and after
        (per rad/s, [re, im]), relative to A_c over the band's half-width (A' w_c / A_c), and
        the model's fast-model E with each (keys baseline_E_*: the first use's).
    """
    ac, da0, wc = gain
    runs = list(build(gain))
    fit: Fit = Objective(c0, runs).fit(theta0, starts=1, max_nfev=max_nfev, refresh=1)
    e0, theta, da = fit.E, fit.theta, da0
    for _ in range(rounds):
        step = _slope_step(Objective(c0, runs).at(theta), theta, (ac, da, wc))
        da = da + step
        runs = list(build((ac, da, wc)))
        fit = Objective(c0, runs).fit(theta, starts=1, max_nfev=max_nfev, refresh=1)
        theta = fit.theta
        if abs(step) < 0.02 * abs(da):
            break
    if fit.E >= e0 or abs(da * wc / ac) > MAX_RELATIVE_SLOPE:  # nothing gained, or no coil's slope: the
        # read-out's drive kept (a slope past a coil's is the baseline bending the drive to an effect it misses:
        # on the jointed beam with a neighbouring mode hidden, -6.6 + 1.3i)
        info = _info(gain, gain, e0, e0)
        if fit.E < e0:
            info["slope_rejected"] = [float((da * wc / ac).real), float((da * wc / ac).imag)]
        return gain, list(build(gain)), info
    return (ac, da, wc), runs, _info(gain, (ac, da, wc), e0, fit.E)


def _info(before: Gain, after: Gain, e_before: float, e_after: float) -> dict:
    rel = lambda g: complex(g[1] * g[2] / g[0])  # noqa: E731  A' w_c / A_c: the relative change per unit w / w_c
    return {"modal_constant": [before[0].real, before[0].imag], "w_c_rad_s": before[2],
            "slope_read_out": [before[1].real, before[1].imag], "slope_refined": [after[1].real, after[1].imag],
            "relative_slope_read_out": [rel(before).real, rel(before).imag],
            "relative_slope_refined": [rel(after).real, rel(after).imag],
            "baseline_E_read_out": float(e_before), "baseline_E_refined": float(e_after)}
