"""Which physical modes each run holds, tracked across an assembly's runs by frequency.

A structure tested over a wide band has several modes, and a campaign's runs may cover
different bands (a narrow slow sweep around one mode, a wide fast chirp over two). Each
mode is calibrated on its own (one amplitude-dependent mode per calibration), so the
modal stage first finds the modes in every run and names each across the runs:

* ``modal_peaks``: the resonances in one run's whole-record FRF (`jointcal.measure.frf`):
  peaks of the displacement ratio |X| inside the driven band (not within `EDGE` of its
  ends) that are coherent (band-averaged coherence >= 0.5: the drive's share of the
  response at least the noise's), prominent (at least `PROMINENCE` times the deeper of
  the two troughs that bound the peak, i.e. 20 dB: a mode of damping zeta stands about
  1 / (2 zeta) over its surroundings, 10 at zeta = 5%), and whose phase turns through
  the half-power band, as a mode's does by 90 deg (at least `PHASE_TURN_DEG`). Noise
  divided by w^2 and a shaker's suspension make peaks of 2-6x near 2 Hz on a real beam
  record, none of them passing; the beam's 18.6 Hz mode stands 160-210x over them.
* ``track_modes``: the peaks of all runs of one assembly grouped by frequency (sorted,
  a new mode wherever the next peak lies more than `GAP` above the last: an amplitude-
  dependent mode softens by a few per cent, neighbouring modes of a structure lie
  further apart), a group kept as a mode when it is found in at least half of the runs
  whose band holds it. Each run whose band holds a mode is read at it, at its own peak
  or, where the run shows none (a low level drowned in noise), at the mode's median
  frequency. A mode is named by its frequency at the lowest level that shows it,
  rounded down (``m18`` for 18.6 Hz). ``mode_hz`` (the config's ``modal.mode_hz``)
  restricts the modes to those nearest the given frequencies.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..io.contract import UNUSABLE

__all__ = ["modal_peaks", "track_modes", "mode_name", "with_modes", "units", "PROMINENCE", "GAP", "PHASE_TURN_DEG",
           "COHERENCE"]

PROMINENCE = 10.0  # a mode stands this many times over the troughs that bound it (20 dB)
COHERENCE = 0.5  # the drive's share of the response at the peak at least the noise's
PHASE_TURN_DEG = 45.0  # a mode's phase turns by 90 deg across its half-power band; noise ripples do not
GAP = 0.12  # relative frequency step between sorted peaks that starts a new mode
EDGE = 0.02  # a peak within this fraction of the driven span from its ends is the band's, not a mode's


def modal_peaks(f: NDArray, X: NDArray, coherence: NDArray, band: tuple[float, float]) -> NDArray:
    """The resonance frequencies of one run's FRF.

    Parameters
    ----------
    f : ndarray, shape (n,)
        Lines of the FRF, Hz (evenly spaced).
    X : complex ndarray, shape (n,)
        Displacement ratio on those lines (in/g, in/lbf or in/V; `jointcal.measure.frf.displacement_ratio`).
    coherence : ndarray, shape (n,)
        Band-averaged coherence on those lines, 0..1.
    band : (lo, hi)
        The driven band, Hz.

    Returns
    -------
    ndarray
        Peak frequencies (Hz) of the lines that pass the module's tests, the highest peak of |X| first.
    """
    from scipy import signal  # here, not at the top: the workflow imports this module to name its jobs (`units`)

    f, X, coherence = (np.asarray(v) for v in (f, X, coherence))
    lo, hi = sorted(band)
    a = np.abs(X)
    ok = np.isfinite(a) & (a > 0)
    if ok.sum() < 8:
        return np.empty(0)
    la = np.where(ok, np.log(np.where(ok, a, 1.0)), np.log(a[ok].min()))
    peaks, props = signal.find_peaks(la, prominence=np.log(PROMINENCE))
    phase = np.unwrap(np.angle(np.where(ok, X, 1.0)))
    out = []
    for i in peaks:
        if not (lo + EDGE * (hi - lo) < f[i] < hi - EDGE * (hi - lo)) or coherence[i] < COHERENCE:
            continue
        il, ir = i, i
        while il > 0 and a[il - 1] >= a[i] / np.sqrt(2):
            il -= 1
        while ir < a.size - 1 and a[ir + 1] >= a[i] / np.sqrt(2):
            ir += 1
        if ir - il >= 2 and np.degrees(abs(phase[ir] - phase[il])) >= PHASE_TURN_DEG:
            out.append((-a[i], float(f[i])))
    return np.asarray([fi for _, fi in sorted(out)])


def mode_name(f_hz: float) -> str:
    """A mode's name from its low-level frequency: ``m`` and the whole hertz below it (18.6 Hz: ``m18``)."""
    return f"m{int(np.floor(f_hz))}"


def _groups(freqs: NDArray) -> list[NDArray]:
    """Sorted frequencies split wherever one lies more than GAP above the previous."""
    freqs = np.sort(freqs)
    if freqs.size == 0:
        return []
    cut = np.flatnonzero(freqs[1:] > freqs[:-1] * (1 + GAP)) + 1
    return np.split(freqs, cut)


def track_modes(peaks: Mapping[str, Sequence[float]], bands: Mapping[str, tuple[float, float]],
                levels: Mapping[str, float], *, mode_hz: float | Sequence[float] | None = None) -> pd.DataFrame:
    """The modes of one assembly and the runs that hold each.

    Parameters
    ----------
    peaks : mapping of run_id to sequence of float
        Each run's resonance frequencies (Hz, `modal_peaks`: the highest peak first, which a run showing
        two peaks inside one mode's group is read at); runs without a record map to [].
    bands : mapping of run_id to (lo, hi)
        Each run's driven band, Hz.
    levels : mapping of run_id to float
        Each run's drive level (any unit): a mode is named at the lowest level that shows it.
    mode_hz : float or sequence of float, optional
        Keep only the modes nearest these frequencies (Hz); a frequency no detected mode lies
        within GAP of is read as a mode of its own, at that frequency.

    Returns
    -------
    DataFrame
        One row per (run, mode) read: ``run_id``, ``mode``, ``f_guess_hz`` (where the run's read-out
        of the mode starts: its own peak, or the mode's median frequency where it shows none),
        ``detected`` (bool). Modes in ascending frequency, runs in the order of `bands`.
    """
    all_f = np.concatenate([np.asarray(p, float) for p in peaks.values()] or [np.empty(0)])
    modes = []  # (median Hz, low-level Hz, {run: peak})
    for g in _groups(all_f):
        g_lo, g_hi = g.min() / (1 + GAP / 2), g.max() * (1 + GAP / 2)
        found = {}
        for r, p in peaks.items():
            inside = [x for x in p if g_lo <= x <= g_hi]  # highest first (`modal_peaks`)
            if inside:
                found[r] = inside[0]
        holding = [r for r, (lo, hi) in bands.items() if min(lo, hi) < np.median(g) < max(lo, hi)]
        if len(found) >= max(1, len(holding)) / 2:
            low = min(found, key=lambda r: (levels.get(r, np.inf), r))
            modes.append((float(np.median(list(found.values()))), found[low], found))
    if mode_hz is not None:
        wanted = np.atleast_1d(np.asarray(mode_hz, float))
        kept = []
        for w in wanted:
            near = min(modes, key=lambda m: abs(np.log(m[0] / w)), default=None)
            if near is not None and abs(np.log(near[0] / w)) <= np.log(1 + GAP):
                kept.append(near)
            else:
                kept.append((float(w), float(w), {}))
        modes = list({id(m): m for m in kept}.values())
    rows, used = [], set()
    for median, low, found in sorted(modes, key=lambda m: m[0]):
        name = mode_name(low)
        if name in used:  # two modes within one hertz: the tenth tells them apart
            name = f"{name}_{low:.1f}".replace(".", "p")
        used.add(name)
        for r, (lo, hi) in bands.items():
            if r in found or min(lo, hi) < median < max(lo, hi):
                rows.append(dict(run_id=r, mode=name, f_guess_hz=found.get(r, median), detected=r in found))
    return pd.DataFrame(rows, columns=["run_id", "mode", "f_guess_hz", "detected"])


def with_modes(table: pd.DataFrame) -> pd.DataFrame:
    """A modal table with its ``mode`` column (text, empty for a run read at none); a table without one
    (made before modes were tracked, or by hand) holds one mode per assembly, named by its resonance at
    the assembly's lowest level."""
    from ..io import level_column

    if "mode" in table.columns:
        return table.assign(mode=table["mode"].fillna("").astype(str))
    level = level_column(table.columns)
    f = pd.to_numeric(table.get("f_res_hz", pd.Series(np.nan, index=table.index)), errors="coerce")
    names = {}
    for asm, g in table[np.isfinite(f)].groupby("assembly", sort=False):
        low = g.sort_values(level, kind="stable") if level else g
        names[asm] = mode_name(float(low["f_res_hz"].iloc[0]))
    return table.assign(mode=table["assembly"].map(names).fillna("m0"))


def units(table: pd.DataFrame) -> list[tuple[str, str]]:
    """The (assembly, mode) pairs calibrated: each mode read in usable runs at two levels or more.

    An assembly none of whose modes has two levels keeps its mode read in the most usable runs (or,
    with none usable, its first), so that its calibration stops with the sentence that names the cause.

    Parameters
    ----------
    table : DataFrame
        ``modal_properties.csv`` (``assembly``, ``mode``, ``flags``, ``f_res_hz`` and a level column,
        `jointcal.io.level_column`; without ``mode``, one mode per assembly: `with_modes`).

    Returns
    -------
    list of (str, str)
        In the order of the assemblies' first rows, modes by ascending frequency.
    """
    from ..io import level_column

    t = with_modes(table)
    t = t[t["mode"] != ""]
    level = level_column(t.columns)
    f = pd.to_numeric(t.get("f_res_hz", pd.Series(np.nan, index=t.index)), errors="coerce")
    usable = t[~t["flags"].fillna("").astype(str).str.contains(UNUSABLE) & np.isfinite(f)]
    out = []
    for asm, g in t.groupby("assembly", sort=False):
        u = usable[usable["assembly"] == asm]
        order = f[g.index].groupby(g["mode"], sort=False).median().sort_values(na_position="last").index
        n_levels = u.groupby("mode")[level].nunique() if level and len(u) else pd.Series(dtype=int)
        kept = [m for m in order if n_levels.get(m, 0) >= 2]
        if not kept:
            counts = u["mode"].value_counts()
            kept = [counts.index[0] if len(counts) else order[0]]
        out += [(str(asm), str(m)) for m in kept]
    return out
