"""Resonance and damping of one run from its envelopes: lag-corrected quadrature, else the envelope peak.

Private: `jointcal.measure.modal.modal_properties` calls `envelope_estimates`. The steps,
in order: the frames used, the envelope peak and its half-power damping, the quadrature
crossing and the sweep's lag there (docs/physics.md, "Phase quadrature" and "Swept-sine
lag"), the phase-resonance damping, the quality flags.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..io.contract import REFERENCE
from ..spectral import parabola_vertex
from ..units import G
from .peaks import anchored_phase, envelope, full_drive, half_power, phase_crossing, transmissibility

__all__ = ["envelope_estimates"]

EDGE = 0.02  # a transmissibility peak within this fraction of the driven span from its edge lies outside the band
NAN_ROW = dict(f_res_hz=np.nan, f_crossing_hz=np.nan, f_peak_hz=np.nan, zeta_half_power=np.nan,
               zeta_phase_resonance=np.nan, q_in=np.nan, response_g=np.nan, base_g=np.nan, eta_value=np.nan,
               group_delay_s=np.nan, snr_db=np.nan, h2_ratio=np.nan, h3_ratio=np.nan, f_res_method="none")


def envelope_estimates(env: pd.DataFrame, row: dict, kind: str, rate_hz_per_s: float, mass_lbf: float,
                       eta_max: float, snr_min_db: float) -> tuple[dict, list[str]]:
    """The envelope columns of one row of modal_properties.csv and the flags they raise.

    Parameters are `jointcal.measure.modal.modal_properties`'; ``kind`` is the run's
    excitation. ``eta_value`` (the sweep-rate parameter of the read-out) and ``q_peak_env``
    (the largest envelope displacement, in) are returned for the caller to use and drop.
    """
    flags: list[str] = []
    if len(env) == 0:
        return dict(NAN_ROW), flags
    use = env["drive_on"].to_numpy(bool) & ~env["bad"].to_numpy(bool)
    if env["bad"].any():
        flags.append("bad_samples")
    e = env[use]
    if len(e) < 8:
        return dict(NAN_ROW), flags
    f, Rf, R, Z = e["f_drive_hz"].to_numpy(), envelope(e, "ref"), envelope(e, "resp"), envelope(e, "z")
    ip = int(np.argmax(np.abs(R)))
    f_peak = _peak_frequency(f, np.abs(R), ip)
    edge = _peak_at_edge(f, transmissibility(e), full_drive(env)[use])
    lo, hi = half_power(f, np.abs(R), ip)
    zeta_hp = (hi - lo) / (2 * f_peak) if np.isfinite(lo + hi) else np.nan
    if not np.isfinite(zeta_hp):
        flags.append("no_half_power")
    sgn = 1.0 if row["f_stop_hz"] > row["f_start_hz"] else -1.0
    read = _quadrature(e, f, Rf, R, Z, kind, f_peak, rate_hz_per_s, eta_max, sgn)
    if read is None:
        if kind != "voltage":  # a drive voltage is not the force: its phase has no quadrature meaning
            flags.append("no_quadrature")
        read = dict(f_x=f_peak, q=float(np.abs(Z[ip])), a_resp=float(np.abs(R[ip])), a_ref=float(np.abs(Rf[ip])),
                    f_res=f_peak, method="peak", tau_g=np.nan)
    zeta_pr = _phase_resonance_zeta(read, kind, mass_lbf)
    zeta_eta = zeta_pr if np.isfinite(zeta_pr) else zeta_hp
    f_res = read["f_res"]
    eta = rate_hz_per_s / (f_res * zeta_eta) ** 2 if np.isfinite(zeta_eta) and zeta_eta > 0 else np.nan
    if edge and kind == "base":  # an open-loop reference drops out at resonance: the FRF fit checks instead
        flags.append("resonance_outside_band")
    noise = float(np.median(e["noise_g"]))
    snr = 20 * np.log10(read["a_resp"] / noise) if noise > 0 else np.inf
    if snr < snr_min_db:
        flags.append("low_snr")
    a_ref = read["a_ref"]
    out = dict(f_res_hz=float(f_res), f_crossing_hz=float(read["f_x"]), f_peak_hz=float(f_peak),
               zeta_half_power=float(zeta_hp), zeta_phase_resonance=float(zeta_pr), q_in=float(read["q"]),
               response_g=float(read["a_resp"]), base_g=float(a_ref) if kind == "base" else np.nan,
               eta_value=float(eta), group_delay_s=float(read["tau_g"]), snr_db=float(snr),
               h2_ratio=float(e["h2_amp_g"].iloc[ip] / abs(R[ip])), h3_ratio=float(e["h3_amp_g"].iloc[ip] / abs(R[ip])),
               f_res_method=read["method"], q_peak_env=float(np.abs(Z).max()))
    if kind != "base":
        out[REFERENCE[kind]] = float(a_ref)
    return out, flags


def _peak_frequency(f: NDArray[np.float64], a: NDArray[np.float64], ip: int) -> float:
    """The envelope's peak frequency (Hz): the parabola through the largest frame and its neighbours."""
    if not 0 < ip < len(f) - 1:
        return f[ip]
    return f[ip] + parabola_vertex(*a[ip - 1:ip + 2])[0] * (f[ip + 1] - f[ip - 1]) / 2


def _peak_at_edge(f: NDArray[np.float64], T: NDArray[np.complex128], full: NDArray[np.bool_]) -> bool:
    """True when the transmissibility peaks at the driven span's edge (a resonance outside the band).

    Frames at full drive only: ramps divide a ringing response by a vanishing base.
    """
    ff = f[full]
    f_T = ff[int(np.argmax(np.abs(T)[full]))]
    return bool(min(f_T - ff.min(), ff.max() - f_T) < EDGE * (ff.max() - ff.min()))


def _quadrature(e: pd.DataFrame, f: NDArray, Rf: NDArray, R: NDArray, Z: NDArray, kind: str, f_peak: float,
                rate_hz_per_s: float, eta_max: float, sgn: float) -> dict | None:
    """The lag-corrected quadrature read-out, or None where the phase never reaches quadrature.

    Quadrature: z leads the base acceleration (or a_resp leads the force) by +90 deg.
    The crossing seen along a sweep lags the steady state by the group delay tau_g:
    1/(zeta omega) for a quasi-steady sweep (method 'quadrature'), the measured phase
    slope beyond ``eta_max`` (method 'quadrature_slope'); f_res = f_crossing - sgn rate tau_g.
    """
    force = kind == "force"
    ph = anchored_phase(Z / Rf if not force else R / Rf, np.pi / 2)
    cross = phase_crossing(f, ph, np.pi / 2, f_peak) if kind != "voltage" else None
    if cross is None:
        return None
    i, w = cross
    t_e = e["time_s"].to_numpy()
    f_x, t_x = (a[i] + w * (a[i + 1] - a[i]) for a in (f, t_e))
    q, a_resp, a_ref = (float(a[i] + w * (a[i + 1] - a[i])) for a in (np.abs(Z), np.abs(R), np.abs(Rf)))
    z_guess = a_ref * G / (2 * (2 * np.pi * f_x) ** 2 * q) if not force else 0.02
    tau_g = _slope_delay(f, ph, i, f_x, z_guess)
    rate = _local_rate(f, t_e, t_x, rate_hz_per_s)
    # Quasi-steady sweeps lag by the phase relaxation time at fixed amplitude, 1/(zeta omega); the slope
    # seen along the sweep also holds the resonance moving with amplitude (a softening joint's backbone),
    # which overstates the lag. Beyond eta_max the measured zeta is itself corrupted by the transient.
    if not force and np.isfinite(z_guess) and z_guess > 0 and rate / (f_x * z_guess) ** 2 <= eta_max:
        tau_g, method = 1.0 / (2 * np.pi * f_x * z_guess), "quadrature"
    else:
        method = "quadrature_slope"
    return dict(f_x=f_x, q=q, a_resp=a_resp, a_ref=a_ref, f_res=f_x - sgn * rate * tau_g, method=method,
                tau_g=tau_g)


def _slope_delay(f: NDArray, ph: NDArray, i: int, f_x: float, z_guess: float) -> float:
    """Group delay (s) from the phase slope over the frames within +-zeta f/2 of the crossing."""
    near = np.abs(f - f_x) <= max(0.5 * z_guess * f_x, 2.5 * np.median(np.abs(np.diff(f))))
    slope = np.polyfit(f[near], ph[near], 1)[0] if near.sum() >= 3 else (ph[i + 1] - ph[i]) / (f[i + 1] - f[i])
    return abs(slope) / (2 * np.pi)


def _local_rate(f: NDArray, t_e: NDArray, t_x: float, rate_hz_per_s: float) -> float:
    """The sweep rate (Hz/s) at the crossing (controllers deviate from linear sweeps); the ridge's otherwise."""
    local = np.abs(np.gradient(f, t_e)) if len(f) > 2 else np.array([rate_hz_per_s])
    rate = float(np.interp(t_x, t_e, local)) if np.all(np.isfinite(local)) else rate_hz_per_s
    return rate if 0 < rate < 10 * rate_hz_per_s else rate_hz_per_s


def _phase_resonance_zeta(read: dict, kind: str, mass_lbf: float) -> float:
    """Energy balance at quadrature (docs/physics.md, "Phase quadrature"); NaN for a peak read-out.

    Base: zeta = |a_base| / (2 omega^2 q); force: zeta = |F| / (2 m |a|) with the moving mass m.
    """
    if not read["method"].startswith("quadrature"):
        return np.nan
    if kind == "force":
        return read["a_ref"] / (2 * (mass_lbf / G) * read["a_resp"] * G)
    omega = 2 * np.pi * read["f_res"]
    return read["a_ref"] * G / (2 * omega**2 * read["q"])
