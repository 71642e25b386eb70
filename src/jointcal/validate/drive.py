"""How a measured run drives the model: its reference channel cleaned, and for a force or a
voltage, through the campaign's modal constant (see `jointcal.validate.runs`).

* base-driven (the Ministack): the base acceleration itself;
* force- and voltage-driven (one mode): the modal force per unit modal mass A(w) r(t), the
  reference through the run's modal constant A(w) = A_c + A' (w - w_c) (held beyond +-45%
  of w_c), applied line by line to the record's spectrum. The calibrated mode responds to
  it as to a base acceleration -A r on a fixed base.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..io.contract import LEVEL, REFERENCE, level_column
from ..models import MinistackModel, fractional_delay, simulate
from ..units import G

__all__ = ["reference_column", "clean_base", "drive_gain", "gain_at", "equivalent_base", "model_input",
           "dwell_gain", "delay_reference", "response_to", "simulate_record"]


def reference_column(record: pd.DataFrame) -> str:
    """The record's reference channel: base_accel_g, force_lbf or drive_V."""
    cols = [c for c in REFERENCE.values() if c in record.columns]
    if len(cols) != 1:
        raise ValueError(f"a run record needs exactly one reference channel ({', '.join(REFERENCE.values())}); "
                         f"it has {', '.join(map(str, record.columns))}.")
    return cols[0]


def clean_base(record: pd.DataFrame, column: str = "base_accel_g") -> NDArray[np.float64]:
    """A reference channel as the model's input: NaN/inf bridged linearly, median removed, shape (N,)."""
    x = record[column].to_numpy(dtype=float).copy()
    ok = np.isfinite(x)
    if not ok.any():
        raise ValueError(f"the {column} channel holds no finite sample; the run cannot drive a simulation.")
    if not ok.all():
        i = np.arange(x.size)
        x[~ok] = np.interp(i[~ok], i[ok], x[ok])
    return x - np.median(x)


def drive_gain(modal: pd.DataFrame) -> tuple[complex, complex, float] | None:
    """The campaign's modal constant, (A_c, A' per rad/s, w_c rad/s): the median over the swept-mode fits.

    Each run's A (at its f_res_hz) is moved to the common w_c (the median resonance) along its own
    slope; the median of the real and imaginary parts of A_c and A'. Without sweep fits, the dwells'
    (`jointcal.measure.dwell.dwell_mode`'s A of each level, in modal_properties.csv's ``dwell_constant_re``
    and ``_im``): their median, unsloped, at the median of the dwell rows' f_res_hz. None without either.

    A force (a ``level_lbf`` table) drives the mode through a real, flat constant (1/m at the driving point):
    the median of |A| with the sign of A's real part (`_signed_abs`), no slope. A phase the read-out found there (`jointcal.measure.sweepfit`: a response
    channel that lags the force channel) is the channels', not the drive's: the model is driven without it,
    so the validation and the discrepancy stage see it (its ``channel_delay``).
    """
    need = ("modal_constant_re", "modal_constant_im", "modal_slope_re", "modal_slope_im", "f_res_hz")
    if not all(c in modal.columns for c in need):
        return _real_if_force(modal, dwell_gain(modal))
    ok = modal[list(need)].apply(pd.to_numeric, errors="coerce").dropna()
    if ok.empty:
        return _real_if_force(modal, dwell_gain(modal))
    w = 2 * np.pi * ok["f_res_hz"].to_numpy()
    wc = float(np.median(w))
    a = ok["modal_constant_re"].to_numpy() + 1j * ok["modal_constant_im"].to_numpy()
    da = ok["modal_slope_re"].to_numpy() + 1j * ok["modal_slope_im"].to_numpy()
    if level_column(modal.columns) == LEVEL["force"]:
        return complex(np.median(_signed_abs(a))), 0j, wc
    ac = a + da * (wc - w)
    med = lambda z: complex(np.median(z.real), np.median(z.imag))  # noqa: E731
    return med(ac), med(da), wc


def _real_if_force(modal: pd.DataFrame, gain: tuple[complex, complex, float] | None):
    """A force's modal constant as `drive_gain` takes it: |A|, no slope (other drives: as given)."""
    if gain is None or level_column(modal.columns) != LEVEL["force"]:
        return gain
    return complex(_signed_abs(np.array([gain[0]]))[0]), 0j, gain[2]


def _signed_abs(a: NDArray[np.complex128]) -> NDArray[np.float64]:
    """|A| with the sign of A's real part: a force's modal constant without the channels' phase (a response
    sensor away from the driving point can read a negative real residue; a channel's lag turns A by well
    under 90 deg)."""
    return np.abs(a) * np.where(a.real < 0, -1.0, 1.0)


def dwell_gain(modal: pd.DataFrame) -> tuple[complex, complex, float] | None:
    """The dwells' modal constant in `drive_gain`'s form (its slope 0), or None (no level of three dwells)."""
    need = ("dwell_constant_re", "dwell_constant_im", "f_res_hz")
    if not all(c in modal.columns for c in need):
        return None
    ok = modal[list(need)].apply(pd.to_numeric, errors="coerce").dropna()
    if ok.empty:
        return None
    return (complex(np.median(ok["dwell_constant_re"]), np.median(ok["dwell_constant_im"])), 0j,
            float(2 * np.pi * np.median(ok["f_res_hz"])))


def gain_at(gain: tuple[complex, complex, float], f_hz: NDArray) -> NDArray[np.complex128]:
    """The modal constant A(w) = A_c + A' (w - w_c) at frequencies f (Hz), held beyond +-45% of w_c."""
    ac, da, wc = gain
    w = 2 * np.pi * np.asarray(f_hz, dtype=float)
    return ac + da * np.clip(w - wc, -0.45 * wc, 0.45 * wc)


def delay_reference(row: Mapping) -> float:
    """The frequency (rad/s) from which a model's channel delay tau is counted for the run's drive: the drive
    is turned by +w tau there.

    A voltage's modal constant A_c is read from the response channel at w_c (the median resonance), so it
    holds the channel's phase there, -w_c tau with the coil's: a model that delays its channel by tau adds
    only -(w - w_c) tau to it. A force drives through its real |A| (`drive_gain`: the channels' phase is left
    in the data) and a base through itself: 0, the whole -w tau.
    """
    gain = row.get("drive_gain")
    return float(gain[2]) if gain is not None and level_column(row) == LEVEL["voltage"] else 0.0


def equivalent_base(row: Mapping, f_hz: NDArray) -> NDArray[np.complex128] | None:
    """The equivalent base acceleration per unit reference at frequencies f, -A(w) / G (g per lbf or per V),
    for a force or voltage run with its ``drive_gain``; None for a base drive (the reference is the base).

    The model responds to a reference phasor R as to the base acceleration -A R / G: its
    response channel reads Y = -(A / G) (T - s) R, T the base rig's transmissibility and s the
    sensor's gain and delay (`simulate_record`)."""
    gain = row.get("drive_gain")
    if gain is None or level_column(row) == LEVEL["base"]:
        return None
    return -gain_at(gain, f_hz) / G


def _through_gain(r: NDArray, fs: float, gain: tuple[complex, complex, float]) -> NDArray:
    """A(w) applied line by line to a real record (positive frequencies; the negative ones conjugate)."""
    n = 1 << int(np.ceil(np.log2(2 * r.size)))
    a = gain_at(gain, np.fft.rfftfreq(n, 1.0 / fs))
    return np.fft.irfft(np.fft.rfft(r, n) * a, n)[:r.size]


def model_input(record: pd.DataFrame, row: Mapping) -> tuple[NDArray[np.float64], str]:
    """The model's input as a base acceleration (g), and the reference column (see the module docstring)."""
    col = reference_column(record)
    x = clean_base(record, col)
    if col == REFERENCE["base"]:
        return x, col
    gain = row.get("drive_gain")
    if gain is None:
        raise ValueError(f"run {row.get('run_id', '?')}: a {col} reference drives the model through the mode's "
                         "modal constant, and the modal stage found none (no swept-mode fit and no level of three dwells "
                         "in the campaign); "
                         "the run cannot be simulated.")
    return -_through_gain(x, float(row["sample_rate_hz"]), gain) / G, col


def response_to(model: MinistackModel, a_b: NDArray, fs: float, *, relative: bool) -> NDArray[np.float64]:
    """The model's response channel (g) to the input a_b (g, shape (N,), sampled at fs Hz): the absolute
    acceleration for a base drive; with ``relative`` (a fixed base forced by -m a_b: a force or voltage drive)
    the mass's acceleration relative to the base, read through the same sensor gain and delay."""
    y = simulate(model, a_b, fs).response_g
    if relative:
        y = y - model.sensor_gain * (fractional_delay(a_b, model.sensor_delay_s, fs) if model.sensor_delay_s else a_b)
    return y


def simulate_record(model: MinistackModel, record: pd.DataFrame, row: Mapping) -> pd.DataFrame:
    """The record the model would give: measured time and reference columns, simulated response (g).

    Samples where the measured reference is not finite are NaN in the simulated response too,
    so the same frames are left out of both envelopes.
    """
    turn = delay_reference(row) * float(model.sensor_delay_s)
    if turn:  # the drive's A_c holds the channel's delay at w_c (`delay_reference`)
        ac, da, wc = row["drive_gain"]
        row = {**row, "drive_gain": (ac * np.exp(1j * turn), da * np.exp(1j * turn), wc)}
    a_b, col = model_input(record, row)
    y = response_to(model, a_b, float(row["sample_rate_hz"]), relative=col != REFERENCE["base"])
    y[~np.isfinite(record[col].to_numpy(dtype=float))] = np.nan
    out = record[["time_s", col]].copy()
    out["response_accel_g"] = y
    return out
