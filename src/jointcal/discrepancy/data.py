"""Measured envelopes of one assembly, as the discrepancy fits use them.

Per usable run: the frames of its envelopes (drive on, not bad, at full drive, within
a band around the measured resonance), their drive frequency, base amplitude, measured
transmissibility response/base, the signed sweep rate, and the repeat-scatter scale of
each frame's magnitude (dB) and phase (deg), the same bins as the validation error E
(`jointcal.validate.error`); and the run's drive as the envelopes measured it (every such
frame's time, drive frequency and base amplitude, and the envelopes' window length,
`jointcal.measure.envelopes.window_length`), which the swept envelope model follows
(`jointcal.models.swept`). A force or voltage drive is the equivalent base's complex envelope:
its magnitude and its phase against the sweep (`SweepDrive.phase_rad`), over every frame from
the run's first to its last (the open-loop force's dip at resonance included).

A frame whose window (its time +- L / 2) reaches past the sweep's commanded span (from f_start to f_stop
at the manifest's rate, placed in time by the drive-on frames) is not used (`within_sweep`): it averages
the drive's start or stop, a ringing response over a vanishing reference. The base rig's full-drive fraction (0.8)
leaves most of them out; an open-loop force's (0.05, for its dip at resonance) kept the last frame of
every run. On the jointed beam with a neighbouring mode hidden (force rig, seed 1), that frame alone
(128.17 Hz, the drive at 37% of full) was off its own time simulation by 2.8 dB and 24 deg in the fast
model (the neighbour's term is steady: it does not ring on when the drive stops), 40 and 45 sigma, and
carried each eta-2 run's E from 1.7 to 5.0 and the neighbour's held-out score to 3.9.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..models import SweepDrive
from ..measure.envelopes import ZETA_MIN, window_length
from ..measure.peaks import full_drive, transmissibility
from ..io import level_column
from ..io.contract import UNUSABLE
from ..validate.drive import equivalent_base
from ..validate.error import BINS
from ..validate.runs import full_drive_fraction

__all__ = ["RunEnvelope", "run_envelope", "run_zeta", "scale_arrays", "within_sweep", "MIN_FRAMES"]

MIN_FRAMES = 5  # frames in the band a run needs (a fast chirp's long windows leave 7-10 around its mode)


@dataclass(frozen=True)
class RunEnvelope:
    """One run's measured envelope frames (all arrays shape (n,)).

    f_hz : drive frequency, Hz; base_g : base amplitude, g (a force or voltage drive: the equivalent
    base amplitude |A(w)| |r| / G, `jointcal.validate.drive.equivalent_base`); T : measured response over
    reference (g/g, g/lbf or g/V); level : the run's level in its own unit (g, lbf or V);
    equivalent_base : -A(w) / G per frame for a force or voltage drive (None for a base drive): the
    model's response channel reads equivalent_base (T_model - s), s the sensor (`fit.observed`);
    sigma_db, sigma_deg : repeat scatter of magnitude and phase at each frame; rate : signed
    sweep rate df/dt, Hz/s; row : the manifest/modal row (run_id, its level, direction,
    sequence, f_res_hz, zeta_phase_resonance, ...); t_s : frame times, s; drive : the run's
    measured drive (None: frames taken as a constant-rate sweep, no transient integrated).
    Measurements only: the model's sweep-transient factor belongs to the objective (`fit.Objective`).
    """

    f_hz: NDArray[np.float64]
    base_g: NDArray[np.float64]
    T: NDArray[np.complex128]
    sigma_db: NDArray[np.float64]
    sigma_deg: NDArray[np.float64]
    rate: float
    row: dict
    t_s: NDArray[np.float64] | None = None
    drive: SweepDrive | None = None
    level: float = float("nan")
    equivalent_base: NDArray[np.complex128] | None = None

    @cached_property
    def drive_rates(self) -> tuple[NDArray, NDArray] | None:
        """df/dt (Hz/s) and dlog A/dt (1/s) of the drive at the frames (None without a drive): computed
        once per run, as every evaluation of the fast model reads them."""
        if self.drive is None or self.t_s is None:
            return None
        return self.drive.at(self.t_s)[2:]


def run_zeta(row: Mapping) -> float:
    """A run's measured damping ratio: the read-out's (``zeta_res``, the modal stage's rule: at phase resonance
    for a base drive, the sweep fit's for a fast chirp), else at phase resonance, else from the half-power
    width (NaN if none)."""
    for key in ("zeta_res", "zeta_phase_resonance", "zeta_half_power"):
        zeta = float(row.get(key, np.nan))
        if np.isfinite(zeta):
            return zeta
    return float("nan")


def scale_arrays(scale: Sequence[Mapping] | pd.DataFrame | None, floor_db: float = 0.05,
                 floor_deg: float = 0.3) -> tuple[NDArray, NDArray]:
    """Per-bin scatter (dB, deg) from the validation's scale table, or the floors."""
    n = len(BINS) - 1
    if scale is None or len(scale) == 0:
        return np.full(n, floor_db), np.full(n, floor_deg)
    t = pd.DataFrame(scale)
    return t["sigma_mag_db"].to_numpy(float), t["sigma_phase_deg"].to_numpy(float)


def _window_s(row: Mapping, zeta_min: float) -> float | None:
    """The envelopes' window length (s) for the run's manifest row, or None when the row lacks the sweep."""
    try:
        fs, rate = float(row["sample_rate_hz"]), float(row["sweep_rate_hz_per_s"])
        f_low = min(float(row["f_start_hz"]), float(row["f_stop_hz"]))
    except (KeyError, TypeError, ValueError):
        return None
    if not (np.isfinite(fs) and np.isfinite(rate) and np.isfinite(f_low) and rate > 0 and f_low > 0):
        return None
    return window_length(fs, rate, f_low, zeta_min=zeta_min) / fs


def within_sweep(t_s: NDArray, f_hz: NDArray, on: NDArray, row: Mapping, window_s: float | None) -> NDArray[np.bool_]:
    """Frames whose envelope window (t -+ L / 2) lies within the sweep's commanded span (all True when the
    row lacks the sweep or the window is unknown).

    The span is [t0, t0 + |f_stop - f_start| / rate], t0 the median over the drive-on frames of where the
    manifest's sweep line through each frame's (t, f) starts: the frames' own drive frequency bends near the
    ends (the ridge: +-0.15-0.3 Hz on the beam's eta-2 runs), so a frame is placed in time, not by its
    frequency. A frame reaching past either end averages the drive's start or stop: a response ringing on
    over a reference that vanishes within the window, which no steady or first-order envelope follows. Frames
    that do not follow the manifest's linear sweep (their median distance from its line above a window's
    sweep, |rate| L) cannot be placed so: all are kept."""
    t, f = np.asarray(t_s, dtype=float), np.asarray(f_hz, dtype=float)
    keep = np.ones(t.shape, bool)
    try:
        f0, f1, rate, L = (float(row["f_start_hz"]), float(row["f_stop_hz"]), abs(float(row["sweep_rate_hz_per_s"])),
                           float(window_s))
    except (KeyError, TypeError, ValueError):
        return keep
    on = np.asarray(on, bool) & np.isfinite(t) & np.isfinite(f)
    if not (np.isfinite([f0, f1, rate, L]).all() and rate > 0 and f1 != f0 and on.any()):
        return keep
    t0 = float(np.median(t[on] - (f[on] - f0) / (np.sign(f1 - f0) * rate)))
    line = f0 + np.sign(f1 - f0) * rate * (t - t0)
    if np.median(np.abs(f[on] - line[on])) > rate * L:  # the frames do not follow the manifest's linear sweep
        return keep
    return (t - L / 2 >= t0) & (t + L / 2 <= t0 + abs(f1 - f0) / rate)


def run_envelope(env: pd.DataFrame, row: Mapping, sigma_db: NDArray, sigma_deg: NDArray, *,
                 band: tuple[float, float] = (0.6, 1.4), max_frames: int = 160,
                 zeta_min: float = ZETA_MIN) -> RunEnvelope | None:
    """The frames of one run used by the discrepancy fits (None when the run is unusable).

    Parameters
    ----------
    env : DataFrame
        The run's envelopes (`jointcal.measure.envelopes.envelopes`).
    row : mapping
        Its modal row (f_res_hz, zeta_res, flags) merged with the manifest row.
    sigma_db, sigma_deg : ndarray, shape (len(BINS) - 1,)
        Repeat scatter per bin of |x| = |f/f_res - 1| / zeta.
    band : (lo, hi)
        Frames kept, as fractions of the measured resonance (wider than E's band: the
        gain, delay and fixture fingerprints live off resonance).
    max_frames : int
        Frames kept at most (evenly thinned): the fits' cost.
    zeta_min : float
        The envelopes' setting of the same name (it sets their window length).
    """
    f_res = float(row.get("f_res_hz", np.nan))
    zeta = run_zeta(row)
    if not (np.isfinite(f_res) and np.isfinite(zeta) and zeta > 0) or UNUSABLE in str(row.get("flags", "")):
        return None
    f = env["f_drive_hz"].to_numpy(float)
    ref = (env["ref_re"] + 1j * env["ref_im"]).to_numpy()
    eq = equivalent_base(row, f)
    if eq is not None:  # a force or voltage: the model is driven by the equivalent base acceleration
        ref = ref * eq
    L = _window_s(row, zeta_min)
    driven = full_drive(env, full_drive_fraction(row))
    driven &= within_sweep(env["time_s"].to_numpy(float), f, env["drive_on"].to_numpy(bool), row, L)
    ok = driven & (f >= band[0] * f_res) & (f <= band[1] * f_res)
    idx = np.flatnonzero(ok)
    if idx.size < MIN_FRAMES:
        return None
    idx = idx[np.unique(np.linspace(0, idx.size - 1, min(max_frames, idx.size)).round().astype(int))]
    t = env["time_s"].to_numpy(float)
    rate = float(np.median(np.gradient(f[ok], t[ok]))) if ok.sum() > 2 else 0.0
    x = np.abs(f[idx] / f_res - 1.0) / zeta
    b = np.clip(np.digitize(x, BINS[1:-1]), 0, len(BINS) - 2)
    ok_t = np.flatnonzero(driven)  # the drive over the whole run: a fast sweep's windows and run-in reach past the band
    if eq is not None:  # a force or voltage: every frame between the run's first and last is its drive, the dip
        # at resonance too (there the envelopes may call the drive off: it is small, not absent)
        span = np.zeros(f.size, bool)
        span[ok_t[0]:ok_t[-1] + 1] = True
        ok_t = np.flatnonzero(span & ~env["bad"].to_numpy(bool) & (np.abs(ref) > 0))
    keep = ok_t[np.r_[True, np.diff(t[ok_t]) > 0]]
    phase = None if eq is None else np.unwrap(np.angle(ref[keep]))  # a force or voltage turns in phase
    drive = (SweepDrive(t[keep], f[keep], np.abs(ref[keep]), L, phase) if L is not None and keep.size >= 4
             else None)
    col = level_column(row)
    return RunEnvelope(f_hz=f[idx], base_g=np.abs(ref[idx]), T=transmissibility(env)[idx], sigma_db=sigma_db[b],
                       sigma_deg=sigma_deg[b], rate=rate, row=dict(row), t_s=t[idx], drive=drive,
                       level=float(row[col]) if col else float("nan"),
                       equivalent_base=None if eq is None else eq[idx])
