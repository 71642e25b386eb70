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
(the read-out's resonance fixes it), as a coil's: A' = A_c s(x) / w_c, s(x) = -i x / (1 + i x)
(`coil_slope`), with one constant, x = w_c L / R >= 0. A coil's phase slope and magnitude tilt
are tied (s lies on the circle |s + 1/2| = 1/2: Re s = -x^2 / (1 + x^2)); a channel delay's slope,
-i w_c tau, is all phase. A free complex slope took the delay into the drive (on the jointed beam
hiding a 400 us delay: -0.005-0.330i against the coil's -0.009-0.093i, and nothing left for the
library's channel_delay to explain); the coil cannot, and leaves the phase it does not tie to a
tilt in the residuals. In turns, the model's parameters by `Objective.fit` and x by a Gauss-Newton
step taken with the model's free parameters linearised beside it (`_coil_step`: a model that can
take up part of the phase, a delay, leaves x to the tilt; x stepped alone zig-zags along that
valley). A coil small against the band (x^2 under the magnitude's scatter) lags as a delay of L / R
does: there the data fix the sum of the two lags, not each.

Every candidate, the recalibration and the time-domain revalidation then take the refined A(w);
the fast model's floor is taken before, with the read-out's, as the validation's simulation was
driven. A baseline that misses (an effect hidden) moves the coil it finds, so each single effect
that fits better than the baseline has the coil refit with it and is scored again on that drive,
and the best there leads (`stage._lead_on_its_drive`); a pair that then leads refits it again, and
a named model once more, from its own fit, before its recalibration. `refine_slope` takes any
candidate. A coil that gains nothing over the read-out's drive is not taken.

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
from .fit import HELD, Candidate, Fit, Objective
from .rule import FLOOR_HIGH

__all__ = ["ROUNDS", "X_MAX", "coil_slope", "refits_slope", "refine_slope"]

ROUNDS = 8  # turns of (joint fit, coil x) at most; they stop once x moves < 2% of itself, or E stops falling
X_MAX = 10.0  # the largest coil x = w_c L / R fitted: a corner R / L a tenth of the mode's frequency
Gain = tuple[complex, complex, float]


def refits_slope(level_unit: str, floor: float | None) -> bool:
    """Whether the stage refits the drive's slope (`refine_slope`): a voltage drive (level unit 'V') whose fast
    model's floor E (None: not measured, taken as 0) is at most `rule.FLOOR_HIGH`, the repeat scatter."""
    return level_unit == "V" and (floor is None or floor <= FLOOR_HIGH)


def coil_slope(x: float) -> complex:
    """The relative slope A' w_c / A_c = d ln A / d ln w at w_c of a coil's 1 / (1 + i w L / R), x = w_c L / R >= 0:
    -i x / (1 + i x), on the circle |s + 1/2| = 1/2 (a magnitude tilt -x^2 / (1 + x^2) tied to the phase slope)."""
    return -1j * x / (1 + 1j * x)


def _coil_step(obj: Objective, theta: NDArray, gain: Gain, x: float) -> float:
    """The Gauss-Newton step of the coil's x = w_c L / R for the residuals of `obj` at theta, the candidate's
    free parameters moving with it (linearised together; the step is x's: a model that can take up part of the
    drive's phase, a channel delay, leaves x to the magnitude tilt, where moving x alone zig-zags along the valley).

    The model's response is taken as proportional to its drive: log T_model changes by d log A(w) / dx dx,
    A = A_c (1 + `coil_slope`(x) u / w_c), u = w - w_c (clipped as `gain_at` clips it)."""
    ac, da, wc = gain
    c = obj.candidate
    idx = np.flatnonzero(c.grown.free_mask(HELD))
    u0 = np.clip(c.to_unit(theta), 1e-6, 1 - 1e-6)
    h = np.where(u0[idx] + 1e-4 <= 1, 1e-4, -1e-4)
    U = np.repeat(u0[None], idx.size + 1, axis=0)
    U[1 + np.arange(idx.size), idx] += h
    R = obj.residuals(c.to_physical(U))
    k, s, ds = 20.0 / np.log(10.0), coil_slope(x), -1j / (1 + 1j * x) ** 2
    col = []
    for run in obj.runs:
        v = np.clip(2 * np.pi * run.f_hz - wc, -0.45 * wc, 0.45 * wc) / wc
        g = ds * v / (1 + s * v)  # d log A / dx
        w = 1.0 / np.sqrt(2.0 * run.f_hz.size * len(obj.runs))  # as the objective weights each run
        col += [k * g.real / run.sigma_db * w, np.degrees(g.imag) / run.sigma_deg * w]
    J = np.c_[((R[1:] - R[0]) / h[:, None]).T, np.concatenate(col)]
    return float(np.linalg.lstsq(J, -R[0], rcond=None)[0][-1])


def refine_slope(c0: Candidate, theta0: NDArray, gain: Gain, build: Callable[[Gain], Sequence[RunEnvelope]], *,
                 max_nfev: int, rounds: int = ROUNDS) -> tuple[Gain, list[RunEnvelope], dict]:
    """The campaign's drive A(w) with its slope refit, as a coil's, with a model on the envelope frames.

    The slope is a coil's, A' = A_c `coil_slope`(x) / w_c, its one constant x = w_c L / R >= 0 fitted:
    the coil's phase slope and magnitude tilt are tied. A phase that turns faster than the magnitude
    tilts is not the coil's: it is left in the residuals, where the library's channel_delay can take
    it (a delay's slope -i w_c tau is all phase; a free complex slope would take it into the drive).

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
        Each fit's effort.

    Returns
    -------
    gain, runs, info
        The refined gain (the read-out's where the coil gains nothing), the runs with it, and for
        diagnosis.json: the slope before and after (per rad/s, [re, im]), relative to A_c over the
        band's half-width (A' w_c / A_c), the coil's x, and the model's fast-model E with each
        (keys baseline_E_*: the first use's).
    """
    ac, da0, wc = gain
    runs = list(build(gain))
    fit: Fit = Objective(c0, runs).fit(theta0, starts=1, max_nfev=max_nfev, refresh=1)
    e0, theta = fit.E, fit.theta
    s0 = complex(da0 * wc / ac)
    x = _coil_x(s0)  # the coil nearest the read-out's slope (held near zero by its ridge)
    da = ac * coil_slope(x) / wc
    runs = list(build((ac, da, wc)))
    for n in range(rounds):
        x_new = float(np.clip(x + _coil_step(Objective(c0, runs).at(theta), theta, (ac, da, wc), x), 0.0, X_MAX))
        if abs(x_new - x) < 0.02 * max(x, 0.01):  # the model leaves the coil where it is: nothing to refit
            break
        trial = list(build((ac, ac * coil_slope(x_new) / wc, wc)))
        again = Objective(c0, trial).fit(theta, starts=1, max_nfev=max_nfev, refresh=1)
        if n and again.E >= fit.E:  # no better than the last x (the first is judged against the read-out's drive)
            break
        moved, x, da, runs, fit, theta = abs(x_new - x), x_new, ac * coil_slope(x_new) / wc, trial, again, again.theta
        if moved < 0.02 * max(x, 0.01):
            break
    if fit.E >= e0:  # nothing gained: the read-out's drive kept
        return gain, list(build(gain)), _info(gain, gain, e0, e0, _coil_x(s0))
    return (ac, da, wc), runs, _info(gain, (ac, da, wc), e0, fit.E, x)


def _coil_x(s: complex) -> float:
    """The coil's x = w_c L / R nearest a relative slope s: from its phase slope, -Im s = x / (1 + x^2) (the
    smaller root; 0 for a lead, 1 past the circle's top)."""
    b = min(max(-s.imag, 0.0), 0.5)
    return 0.0 if b == 0 else (1 - np.sqrt(1 - 4 * b * b)) / (2 * b)


def _info(before: Gain, after: Gain, e_before: float, e_after: float, x: float) -> dict:
    rel = lambda g: complex(g[1] * g[2] / g[0])  # noqa: E731  A' w_c / A_c: the relative change per unit w / w_c
    return {"modal_constant": [before[0].real, before[0].imag], "w_c_rad_s": before[2],
            "slope_read_out": [before[1].real, before[1].imag], "slope_refined": [after[1].real, after[1].imag],
            "relative_slope_read_out": [rel(before).real, rel(before).imag],
            "relative_slope_refined": [rel(after).real, rel(after).imag],
            "coil_x": float(x), "baseline_E_read_out": float(e_before), "baseline_E_refined": float(e_after)}
