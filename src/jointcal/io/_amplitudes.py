"""Amplitude checks of one run record: swapped channels, the reference against the manifest's level,
and (base-driven) the response's units from its ratio to the base below resonance.

Private: `jointcal.io._checks.validate_run` reports what these find as flags
(``swapped``, ``level``, ``units``).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from jointcal.io.contract import LEVEL, QUANTITY, REFERENCE, RESPONSE, UNITS
from jointcal.io._transmissibility import LowRatio, low_frequency_ratio, response_ratio
from jointcal.io._windows import sums, windows

__all__ = ["window_amplitudes", "swap_problem", "level_problems", "low_frequency_ratio"]

LEVEL_RTOL = 0.10  # reference amplitude vs the manifest's level: 10x a controller's normal 1 % ripple
UNIT_RTOL = 0.015  # a ratio this close to a unit factor is named as a units mistake (example: within 0.2 %)
SWAP_PEAK = 2.0  # a controlled reference never peaks at twice its median amplitude over the sweep
RESPONSE_UNIT_BAND = 1.5  # a response scale within this factor of another unit's is named as that unit
# excitation -> {unit a record or level may wrongly be in: the contract unit's size in it}
UNIT_FACTORS = {kind: {u: 1.0 / size for u, size in UNITS[q].items() if size != 1.0} for kind, q in QUANTITY.items()}
PLATEAU = 1.25  # a held drive's amplitude quartiles lie within this ratio (a 1 % ripple: 1.01)


def window_amplitudes(x: NDArray[np.float64], fs: float, f0: float, f1: float, rate: float) -> NDArray[np.float64]:
    """Amplitude of a channel in consecutive windows of ``MIN_CYCLES`` drive cycles over the sweep (unit of `x`).

    Parameters
    ----------
    x : ndarray of float, shape (n,)
        One channel, sampled at `fs` (Hz) from the sweep's start.
    fs : float
        Sample rate (Hz).
    f0, f1, rate : float
        The manifest's linear sweep (Hz, Hz, Hz/s); a free-decay tail after it is left out.

    Returns
    -------
    ndarray of float, shape (k,)
        ``sqrt(2) * RMS`` of each mean-removed window (the amplitude of a sine), for
        the windows of at least 8 samples with more than half of them finite.
    """
    k, m = windows(x.size, fs, f0, f1, rate)
    ok = np.isfinite(x[: k.size])
    v = np.where(ok, x[: k.size], 0.0)
    n_all, n_ok, s1, s2 = sums(k, m, np.ones(k.size), ok.astype(float), v, v * v)
    keep = (n_all >= 8) & (n_ok > 0.5 * n_all)
    mean = s1[keep] / n_ok[keep]
    return np.sqrt(2.0 * np.maximum(s2[keep] / n_ok[keep] - mean**2, 0.0))


def _held(amp: NDArray[np.float64]) -> bool:
    """True when a channel holds one amplitude over the sweep (quartiles within ``PLATEAU``), as a drive does.

    A chirp shorter than its ramps never reaches its level: a record without a plateau
    has no level to read.
    """
    q25, q75 = np.percentile(amp, [25, 75])
    return bool(q25 > 0 and q75 <= PLATEAU * q25)


def _flatness(amp: NDArray[np.float64]) -> float:
    med = float(np.median(amp))
    return float(amp.max() / med) if med > 0 else np.inf


def swap_problem(amp: Mapping[str, NDArray[np.float64]], kind: str, path: object,
                 drop: str) -> list[tuple[str, str]]:
    """(flag, sentence) when the reference and response columns look swapped.

    The reference of every kind is flat over a sweep (a controller holds a base
    acceleration or a force at its level; a generator's voltage is constant), while the
    response peaks at resonance. `amp` holds each column's `window_amplitudes`.
    """
    ref = REFERENCE[kind]
    if min(a.size for a in amp.values()) < 3:
        return []
    flat = {c: _flatness(a) for c, a in amp.items()}
    if flat[ref] > SWAP_PEAK and flat[RESPONSE] < flat[ref] / 2 and _held(amp[RESPONSE]):
        what = "drive voltage" if kind == "voltage" else "controlled reference"
        return [(f"swapped:{ref}",
                 f"{path}: column '{ref}' peaks at {flat[ref]:.3g} times its median amplitude while "
                 f"'{RESPONSE}' stays within {flat[RESPONSE]:.2f} times (the {what} is flat, the "
                 f"response peaks at resonance), so the two columns look swapped; export each channel under "
                 f"its own name {drop}.")]
    return []


def level_problems(chans: Mapping[str, NDArray[np.float64]], amp: Mapping[str, NDArray[np.float64]], kind: str,
                   row: Mapping[str, Any], fs: float, path: object, run: str, drop: str,
                   sources: Mapping[str, Mapping[str, str]]) -> tuple[list[tuple[str, str]], str]:
    """(flag, sentence) for a reference amplitude off the manifest's level and, base-driven, a response in other units;
    and what the response-units check found, for the run's row (``response_units_check``).

    The median window amplitude of the reference is its level: a controller holds a
    base acceleration at it within a ripple, a generator a voltage; an open-loop force
    drops out at resonance, so for a force only a units mistake or a factor of two
    counts. For a base-driven run the response's own scale follows from
    `response_ratio` corrected by the single-mode rise and by the base's units
    mistake if any: it tells whether a base in m/s^2 came with a response in m/s^2 too,
    and names a response in other units than declared. Where the record cannot tell
    (no resonance above the band's bottom, a band starting near it, another mode there,
    no held base level), the note says why; a force- or voltage-driven record holds
    nothing that fixes the response's scale.
    """
    if kind != "base":
        note = f"not checkable: a {kind}-driven record holds nothing that fixes the response's scale"
    else:
        note = "undecided: the base holds no level over the sweep"
    if LEVEL[kind] not in row or min(a.size for a in amp.values()) < 3 or not _held(amp[REFERENCE[kind]]):
        return [], note
    ref = REFERENCE[kind]
    out: list[tuple[str, str]] = []
    level, unit = float(row[LEVEL[kind]]), LEVEL[kind].split("_", 1)[1]
    got = float(np.median(amp[ref]))
    ratio = got / level
    base_scale, resp_scale, low = 1.0, None, None
    if kind == "base":
        low = response_ratio(chans[ref], chans[RESPONSE], fs, float(row["f_start_hz"]), float(row["f_stop_hz"]),
                             float(row["sweep_rate_hz_per_s"]))
        resp_scale = None if isinstance(low, str) else low.scale
        note = f"undecided: {low}" if isinstance(low, str) else note
    rtol = 1.0 if kind == "force" else LEVEL_RTOL
    named = any(abs(ratio / f - 1) <= UNIT_RTOL or abs(ratio * f - 1) <= UNIT_RTOL for f in UNIT_FACTORS[kind].values())
    if not (abs(ratio - 1) <= LEVEL_RTOL or (abs(np.log(ratio)) <= np.log(1 + rtol) and not named)):
        what = {"base": "base", "force": "force", "voltage": "drive"}[kind]
        said = (f"{what} amplitude is {got:.3g} {unit} where the manifest says {LEVEL[kind]} = {level:g} {unit} "
                f"for run {run}")
        msg = (f"{path}: {said} (x{ratio:.3g}, more than {rtol:.0%} off): the manifest's level or the channel's "
               f"sensitivity is wrong; correct {LEVEL[kind]} of run {run} in manifest.csv or the channel's "
               f"calibration {drop}.")
        for other, factor in UNIT_FACTORS[kind].items():
            if abs(ratio / factor - 1) <= UNIT_RTOL:
                base_scale = factor
                msg = f"{path}: {said} (x{ratio:.4g}): " + _record_units(kind, other, factor, unit, resp_scale, drop)
                break
            if abs(ratio * factor - 1) <= UNIT_RTOL:
                msg = (f"{path}: {said} (x1/{1 / ratio:.4g}): is {LEVEL[kind]} written in {other}?; write "
                       f"{LEVEL[kind]} of run {run} in {unit} in manifest.csv {drop}.")
                break
        out.append((f"level:{ref}", msg))
    if isinstance(low, LowRatio):
        scale = low.scale * base_scale  # the response's values / its values in the declared unit
        declared = sources.get(RESPONSE, {}).get("unit", "g")
        note = (f"{declared} confirmed: response/base {low.scale:.3g} below resonance (at {low.f_low:.0f} Hz, one "
                f"mode's rise removed)")
        if base_scale != 1.0 and abs(np.log(scale / base_scale)) <= np.log(RESPONSE_UNIT_BAND):
            note = (f"flagged with the base: response/base {low.scale:.3g} below resonance (at {low.f_low:.0f} Hz), "
                    "one unit for both")
        else:
            found = _response_units(scale, low, sources.get(RESPONSE, {}), path, drop)
            out += found
            if found:
                note = f"flagged: response/base {low.scale:.3g} below resonance (at {low.f_low:.0f} Hz)"
    return out, note


def _record_units(kind: str, other: str, factor: float, unit: str, resp_scale: float | None, drop: str) -> str:
    """The problem and fix of a reference recorded in `other` units, naming the channels to convert."""
    ref = REFERENCE[kind]
    if kind != "base":
        return f"is {ref} in {other}?; export {ref} in {unit} (divide by {factor:g}) {drop}."
    if resp_scale is None:  # the response's own scale is unknown: say when to convert it too
        return (f"is the record in {other}?; export {ref} in {unit} (divide by {factor:g}), and {RESPONSE} too if "
                f"it is in {other}, {drop}.")
    if abs(np.log(resp_scale)) <= np.log(RESPONSE_UNIT_BAND):  # response/base ~ 1: one unit for both
        return f"is the record in {other}?; export {ref} and {RESPONSE} in {unit} (divide by {factor:g}) {drop}."
    return (f"is {ref} in {other}? (below resonance the response reads {resp_scale:.3g} times the base, so the "
            f"response's own unit is right); export {ref} in {unit} (divide by {factor:g}) and leave the response "
            f"as it is {drop}.")


def _response_units(scale: float, low: LowRatio, source: Mapping[str, str], path: object,
                    drop: str) -> list[tuple[str, str]]:
    """(flag, sentence) when a base-driven response reads `scale` times its value in the declared unit."""
    units = UNITS["acceleration"]
    declared = source.get("unit", "g")
    if declared not in units:
        return []
    size = units[declared] / scale  # the unit the values look to be in, in g
    found = [u for u, s in units.items() if u != declared and abs(np.log(size / s)) <= np.log(RESPONSE_UNIT_BAND)]
    if not found:
        return []
    true = found[0]
    name, by = source.get("name", RESPONSE), source.get("by", "name")
    peak = f"the peak above the band's top, {low.f_peak:.0f} Hz" if low.beyond else f"the peak at {low.f_peak:.0f} Hz"
    rises = f"at most {low.rise:.2f}" if low.beyond else f"{low.rise:.2f}"
    if by == "name" and true in ("g", "m/s^2"):
        fix = (f"name the {source.get('noun', 'column')} {'response_accel_g' if true == 'g' else 'response_accel_m_s2'}"
               f" (it holds {true}) or export it in {declared}")
    elif by == "name":
        fix = f"export {RESPONSE} in g (multiply by {units[true]:.6g})"
    elif by == "file":
        fix = f"correct the unit of channel {name!r} in the file (it says {declared}), or its sensitivity"
    else:
        fix = f"give channel {name!r} its unit in the file (it is read as {declared})"
    return [(f"units:{RESPONSE}",
             f"{path}: below resonance (at {low.f_low:.0f} Hz, {peak}) the response read from "
             f"{name!r} as {declared} is {low.ratio:.3g} times the base acceleration where a base-driven structure "
             f"follows its base ({rises} times, rising to its resonance): is it in {true}?; {fix} {drop}.")]
