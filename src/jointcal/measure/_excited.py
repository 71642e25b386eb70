"""Force- and voltage-driven runs: the swept-mode fit of the whole transient, else the whole-record FRF.

Private: `jointcal.measure.modal.modal_properties` calls `sweep_estimate`,
`backbone_estimate` and `excited_readout` by the rule `jointcal.measure.modal.READOUT_RULE`
states.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..io.contract import REFERENCE, RESPONSE, UNUSABLE
from ..units import G
from .backbone import backbone_at_peak, pair_backbone
from .peaks import envelope
from .frf import frf_flags, quadrature_ok, zeta_at_quadrature
from .sweepfit import baseband, fit_swept_mode

__all__ = ["sweep_estimate", "backbone_estimate", "excited_readout", "band_envelope_peak", "modal_constant",
           "channel_lag_text"]

ZETA_MAX = 0.5  # a fitted damping ratio at or above this is no mode
SWEEP_FRAME = 0.05  # a swept-mode fit more than this fraction off the frequency it was fitted in is off its mode
REFIT = (0.02, 0.2)  # a fit this far off its start (fraction) is refitted once, centred on the mode


def backbone_estimate(tab, fit):
    """A voltage's equal-amplitude pair backbone at the peak (NaN when not this mode or too few levels)."""
    if fit is None:
        return np.nan, np.nan
    f_bb, z_bb, _ = backbone_at_peak(pair_backbone(tab["freq_hz"].to_numpy(), envelope(tab, "x"),
                                                   f_guess=fit.f_n_hz, near_frac=3 * fit.zeta))
    if not (np.isfinite(f_bb) and abs(f_bb / fit.f_n_hz - 1) <= 3 * fit.zeta and 0 < z_bb < ZETA_MAX):
        return np.nan, np.nan
    return float(f_bb), float(z_bb)


def excited_readout(env_out, fit, sweep, why, flags, kind, f_bb, z_bb, rate_hz_per_s, eta_max, frf_misfit,
                     mass_lbf, record, row):
    """A force- or voltage-driven run by `jointcal.measure.modal.READOUT_RULE`."""
    flags[:] = [f for f in flags if f != "no_quadrature"]
    quad = quadrature_ok(fit)
    if kind == "force" and quad:  # energy balance at the FRF's quadrature: modal constant G / mass_lbf (1/m)
        env_out["zeta_phase_resonance"] = zeta_at_quadrature(fit) * (G / mass_lbf) / fit.modal_constant
    if sweep is not None:
        q_peak = band_envelope_peak(record, row, kind, sweep.f_hz)
        env_out["sweep_note"] = "; ".join(filter(None, (
            "the record began with the mode already moving: its start state fitted" if sweep.start_fitted else "",
            sweep.coil_text(), channel_lag_text(sweep) if kind == "force" else "")))
        flags += ["sweep_truncated"] * sweep.ringing_end
        return dict(f_res_hz=sweep.f_hz, f_res_method="sweep_fit", q_in=sweep.q_in, zeta_res=sweep.zeta,
                    q_peak_in=q_peak, eta=rate_hz_per_s / (sweep.f_hz * sweep.zeta) ** 2)
    flags.append("sweep_fit_failed")
    env_out["sweep_note"] = why
    if fit is None:
        return dict(f_res_hz=env_out["f_res_hz"], f_res_method=env_out["f_res_method"], q_in=np.nan,
                    zeta_res=np.nan, q_peak_in=np.nan, eta=np.nan)
    if np.isfinite(f_bb):
        f_res, method, zeta = f_bb, "frf_backbone", z_bb
    else:
        f_res, method, zeta = (fit.f_quad_hz if quad else fit.f_n_hz), "frf_fit", fit.zeta
    if kind == "force" and quad:
        zeta = env_out["zeta_phase_resonance"]
    frf_flags(fit, flags, frf_misfit)
    eta = rate_hz_per_s / (f_res * zeta) ** 2 if zeta > 0 else np.inf
    if not eta <= eta_max:  # an FRF read-out of a chirp faster than the mode belongs to no known amplitude
        flags.append(UNUSABLE)
    q_peak = band_envelope_peak(record, row, kind, f_res)
    return dict(f_res_hz=f_res, f_res_method=method, q_in=q_peak, zeta_res=zeta, q_peak_in=q_peak, eta=eta)


def channel_lag_text(sweep) -> str:
    """A force's read-out whose modal constant took a phase (`jointcal.measure.sweepfit`: the response channel
    lags the force channel), in words; empty where A stayed real."""
    a = complex(sweep.modal_constant)
    if not (np.isfinite(a) and a.imag != 0.0):
        return ""
    lag = -float(np.angle(a))
    return (f"the response channel lags the force by {np.degrees(lag):.1f} deg at the mode (a delay of "
            f"{lag / (2 * np.pi * sweep.f_hz) * 1e6:.0f} us, if a delay): A's phase fitted, the model driven through |A|")


def band_envelope_peak(record: pd.DataFrame | None, row: dict, kind: str, f_hz: float,
                       cutoff: float = 0.45) -> float:
    """The response's band-limited envelope peak near the mode, as a displacement amplitude (in).

    The response acceleration demodulated at f_hz and low-passed at cutoff f_hz
    (`jointcal.measure.sweepfit.baseband`: the mode's passage and ring-down, not the drive far from it
    or other modes), its largest magnitude over the good samples, divided by (2 pi f_hz)^2:
    the check of q_in (measured on virtual rigs within 5% of the amplitude the mode reached
    for eta 0.5-50; within 12% for impulse-like chirps, eta 500, whose passage mixes the
    mode with the drive's broadband forced response).
    """
    if record is None or not np.isfinite(f_hz) or f_hz <= 0:
        return np.nan
    a = record[RESPONSE].to_numpy(float) * G
    good = np.isfinite(a)
    if good.sum() < 16:
        return np.nan
    a = np.where(good, a - np.median(a[good]), 0.0)
    fs = float(row["sample_rate_hz"])
    w = 2 * np.pi * f_hz
    env = np.abs(baseband(a, fs, w, cutoff * f_hz))
    near_bad = np.convolve(~good, np.ones(2 * int(3 * fs / (cutoff * f_hz)) + 1), mode="same") > 0
    env = env[~near_bad]
    return float(env.max() / w**2) if env.size else np.nan


def sweep_estimate(record, row, kind, fit, env_out, z_bb, band, max_residual, coil=None):
    """The swept-mode fit (`jointcal.measure.sweepfit`) of a force- or voltage-driven run and, when it is
    not used, why: (SweepFit or None, reason). Started from the FRF read-out (else the envelope peak); the
    fit scans its own damping. Not this mode when its misfit exceeds max_residual, its damping lies
    outside (0, ZETA_MAX) or its resonance outside the band or more than SWEEP_FRAME from the start. coil: a
    voltage drive's coil ('fit' or (w_e, g), `fit_swept_mode`), ignored for other drives."""
    if record is None:
        return None, "no record"
    f0 = fit.f_n_hz if fit is not None else env_out["f_peak_hz"]
    if not (np.isfinite(f0) and f0 > 0):
        return None, "no resonance to start from (no FRF peak, no envelope peak)"
    z0 = next((z for z in (z_bb, fit.zeta if fit is not None else np.nan, env_out["zeta_half_power"])
               if np.isfinite(z) and 1e-4 < z < 0.3), 0.01)
    def fit(f_start, z_start):
        return fit_swept_mode(record[REFERENCE[kind]].to_numpy(float), record[RESPONSE].to_numpy(float),
                              float(row["sample_rate_hz"]), float(f_start), float(z_start),
                              modal_phase=0.0 if kind == "force" else None,
                              coil=coil if kind == "voltage" else None)

    try:
        sw = fit(f0, z0)
        if np.isfinite(sw.f_hz) and 0 < sw.zeta < ZETA_MAX and REFIT[0] < abs(sw.f_hz / f0 - 1) < REFIT[1]:
            f0 = sw.f_hz  # the start was off (an FRF of a bent peak or a fast chirp): again, centred on the mode
            sw = fit(f0, sw.zeta)
    except (ValueError, np.linalg.LinAlgError) as exc:
        return None, f"the fit could not run: {exc}"
    lo, hi = band
    if not (np.isfinite(sw.f_hz) and np.isfinite(sw.zeta)):
        return None, "the fit diverged"
    if sw.residual > max_residual:
        return None, f"misfit {sw.residual:.3f} above modal.sweep_misfit {max_residual:g}: not one mode"
    if not 0 < sw.zeta < ZETA_MAX:
        return None, f"damping {sw.zeta:.3g} outside (0, {ZETA_MAX:g})"
    if not (lo < sw.f_hz < hi and abs(sw.f_hz / f0 - 1) < SWEEP_FRAME):
        return None, (f"resonance {sw.f_hz:.4g} Hz outside the band or more than {SWEEP_FRAME:.0%} from its frame, "
                      f"{f0:.4g} Hz")
    return sw, ""


def modal_constant(sweep) -> dict:
    """The swept-mode fit's modal constant at its resonance, A(w_r), and its slope dA/dw (per rad/s): the
    columns modal_constant_re/_im, modal_slope_re/_im ((in/s^2) per reference unit; NaN without a fit)."""
    if sweep is None:
        return dict(modal_constant_re=np.nan, modal_constant_im=np.nan, modal_slope_re=np.nan, modal_slope_im=np.nan)
    wr = 2 * np.pi * sweep.f_hz
    a = sweep.modal_constant + sweep.modal_slope * (wr / sweep.w0 - 1.0)
    da = sweep.modal_slope / sweep.w0
    return dict(modal_constant_re=a.real, modal_constant_im=a.imag, modal_slope_re=da.real, modal_slope_im=da.imag)
