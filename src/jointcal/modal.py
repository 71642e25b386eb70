"""Measured modal properties of each run, and their scatter across repeats.

From a run's envelopes (`jointcal.signal.envelopes`):

* resonance where the relative displacement z is in quadrature with the base
  acceleration (z leads a_base by 90 deg, i.e. lags the effective force -m a_base by
  90 deg; interpolated crossing), corrected for the sweep's lag: a sweep at rate r
  shows the steady-state phase delayed by the group delay tau_g, so
  f_res = f_crossing - sgn(r) r tau_g (first order in eta). For quasi-steady sweeps
  (eta <= eta_max) tau_g = 1/(zeta omega), the phase relaxation time at fixed amplitude,
  with the phase-resonance zeta (method 'quadrature'); beyond, tau_g = |d phi/d omega|
  from the measured phase slope (method 'quadrature_slope'); beyond eta_frf the
  whole-record FRF's single-mode fit (method 'frf_fit', `jointcal.frf`).
* force- and amplifier-voltage-driven runs (an open-loop shaker: the force drops out
  at resonance, the voltage is not the force, chirps are often fast): the resonance
  and damping of the whole-record H1's single-mode fit ('frf_fit'), as a lab's FRF
  software reads them; for a nonlinear structure the equivalent FRF at that drive
  level. Reported for every run with a record (f_frf_hz, zeta_frf, frf_residual), so
  the envelope and FRF read-outs can be compared. A voltage reference's modal constant
  has an unknown phase, and a nonlinear joint bends the peak: its resonance and damping
  are read from equal-amplitude line pairs, the equivalent-linear pole at the peak's
  amplitude ('frf_backbone', f_backbone_hz, zeta_backbone; `jointcal.frf.pair_backbone`).
  Both need quasi-steady lines; a chirp faster than the joint can follow breaks them. So for
  force- and voltage-driven runs the resonance is finally read from the whole transient:
  one mode with amplitude-dependent frequency and damping driven by the measured reference,
  fitted to the response (`jointcal.sweepfit`, method 'sweep_fit'; f_sweep_hz, zeta_sweep,
  sweep_residual), at the largest amplitude the run reached, which becomes q_in (the
  envelopes' own amplitude stays in q_envelope_in). Kept only when it is this mode (within
  10% of the FRF read-out, envelope misfit <= 0.1; e.g. a sensor off the driving point,
  whose mass line no single mode holds, keeps 'frf_fit').
* the peak of the response envelope (the paper's resonance read-out);
* damping by half-power bandwidth of the response envelope (the paper's estimate),
  and by phase-resonance energy balance at quadrature, zeta = |a_base| / (2 omega^2 q)
  (one amplitude, no bandwidth); force-driven: zeta = |F| / (2 m |a|) (needs the
  moving mass); voltage-driven: none (no absolute force), zeta_frf only.
* group_delay_s: the lag tau_g used for the correction (s);
* quality flags; a flagged value is kept and marked, never dropped. 'unusable' marks a
  row the calibration must not use.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ._contract import LEVEL, REFERENCE, RESPONSE
from .frf import backbone_at_peak, pair_backbone, record_frf, zeta_at_quadrature
from .models import G
from .signal import envelopes
from .sweepfit import baseband, fit_swept_mode

__all__ = ["modal_properties", "measure_run", "scatter", "run_flags", "FLAG_WORDS", "ENVELOPE_COLUMNS"]

ENVELOPE_COLUMNS = ("time_s", "f_drive_hz", "ref_re", "ref_im", "resp_re", "resp_im", "z_re", "z_im", "h2_amp_g",
                    "h3_amp_g", "noise_g", "drive_on", "bad")

FLAG_WORDS = {
    "eta_high": "sweep too fast for quasi-steady envelopes (eta > eta_max)",
    "no_quadrature": "the phase never reaches quadrature; f_res is the envelope peak",
    "resonance_outside_band": "the response peak sits at the edge of the driven band",
    "low_snr": "response at resonance less than snr_min above the noise floor",
    "bad_samples": "NaN/inf or clipped samples; frames touching them were left out",
    "no_half_power": "a half-power point lies outside the record",
    "frf_truncated": "the response had not died out at the record's end; the whole-record FRF leaks",
    "frf_misfit": "the FRF's peak is not one linear mode (fit residual above frf_misfit: a nonlinear "
                  "structure's bent peak, a transient, overlapping modes or noise); zeta_frf and f_frf_hz are "
                  "doubtful, a quadrature read-out less so",
    "sweep_fit_failed": "the whole-transient fit of one mode did not fit (sweep_note says why); the FRF read-out "
                        "is reported at the band-limited envelope peak, usable only for a quasi-steady sweep",
    "units": "the response/base ratio below resonance says the response is in other units than its column "
             "name (ingest's check); the run is left out",
    "unusable": "no resonance could be estimated from this run",
}


def _crossing(x: np.ndarray, target: float) -> np.ndarray:
    """Indices i where x crosses target between i and i+1."""
    d = x - target
    return np.flatnonzero((d[:-1] == 0) | (d[:-1] * d[1:] < 0))


def _interp(i: int, w: float, *arrays):
    return [a[i] + w * (a[i + 1] - a[i]) for a in arrays]


def _half_power(f: np.ndarray, a: np.ndarray, ip: int):
    """Half-power frequencies around the peak index ip of envelope a(f); NaN if not found."""
    level = a[ip] / np.sqrt(2.0)
    lo = hi = np.nan
    left = np.flatnonzero(a[:ip] < level)
    if left.size:
        i = left[-1]
        lo = f[i] + (level - a[i]) * (f[i + 1] - f[i]) / (a[i + 1] - a[i])
    right = np.flatnonzero(a[ip:] < level)
    if right.size:
        i = ip + right[0]
        hi = f[i - 1] + (level - a[i - 1]) * (f[i] - f[i - 1]) / (a[i] - a[i - 1])
    return min(lo, hi), max(lo, hi)


def _kind(row: dict, record: pd.DataFrame | None) -> str:
    """Reference kind of a run ('base', 'force', 'voltage'): from the record's columns, else the level column."""
    cols = record.columns if record is not None else []
    kinds = [k for k, c in REFERENCE.items() if c in cols] or [k for k, c in LEVEL.items() if c in row]
    return kinds[0] if kinds else "base"


def modal_properties(env: pd.DataFrame, row: dict, *, rate_hz_per_s: float, mass_lbf: float = 2.65,
                     eta_max: float = 0.5, eta_frf: float = 4.0, snr_min_db: float = 20.0, frf_span: float = 2.0,
                     frf_misfit: float = 0.02, sweep_misfit: float = 0.1, mode_hz: float | None = None,
                     record: pd.DataFrame | None = None, with_frf: bool = False):
    """Resonance, damping, amplitudes and flags of one run (one row of modal_properties.csv).

    Parameters
    ----------
    env : DataFrame
        The run's envelopes (may be empty when the envelope stage could not process the
        run, e.g. a chirp too short for its window: the FRF path still applies).
    row : mapping
        Its manifest row.
    rate_hz_per_s : float
        Measured sweep rate (Hz/s), from the envelopes' ridge; the local rate at the
        crossing (slope of the tracked drive frequency) is used where it is sound.
    mass_lbf : float
        Weight of the moving mass (lbf), used only for force-driven phase-resonance damping.
    eta_max, eta_frf : float
        Sweep-rate parameter beyond which a run's envelopes and FRF lines are not
        quasi-steady (eta_max: a base-driven run's lag is then corrected by the measured
        phase slope; a force- or voltage-driven run's FRF read-out belongs to no known
        amplitude) and beyond which a base-driven run is read from the FRF fit (eta_frf).
    frf_span : float
        Half-width of the FRF fit band in half-power bandwidths (`jointcal.frf.fit_mode`).
    frf_misfit : float
        Relative RMS residual of the FRF fit above which the run is flagged 'frf_misfit'
        when an FRF read-out is reported (measured on synthetic rigs,
        tests/benchmarks/accept_rigs.py: a linear mode with 0.3% noise fits to 0.07-0.14%,
        a lightly nonlinear 100 Hz jointed beam to 0.4-1.8%, the Table 3.2 joint's bent
        peaks to 1.1-9%, its eta-20 chirps' transients to 9-63%).
    sweep_misfit : float
        Relative RMS misfit of the swept-mode fit above which it is not this mode
        (`jointcal.sweepfit`; measured 0.0002-0.02 on synthetic rigs with 0.3-2% noise,
        0.016-0.017 on the real UNESP beam records).
    mode_hz : float, optional
        Approximate natural frequency (Hz) of the mode to read where the band holds more
        than one: the FRF peak nearest it. Default: for force- and voltage-driven runs the
        largest peak of the displacement ratio (response / reference / w^2) in the band (a
        higher mode's acceleration peak can be the larger), for base-driven runs the
        envelope peak.
    record : DataFrame, optional
        The raw record, for the whole-record FRF (`jointcal.frf`) and the swept-mode fit.
    with_frf : bool
        Also return the FRF table (H1, H2, coherence, fitted displacement ratio).

    Returns
    -------
    props : dict
        One row of modal_properties.csv: ``f_res_hz``, ``zeta_res`` and ``q_in`` read by
        the rule of `readout_rule` (``f_res_method`` names it), every estimator's own
        columns beside them, ``q_peak_in`` (the response's band-limited envelope peak near
        the mode, the check of q_in) and ``flags``.
    frf : DataFrame (only with ``with_frf``)
        `jointcal.frf.record_frf`'s table, or an empty one.
    """
    kind = _kind(row, record)
    out = {k: row[k] for k in ("run_id", "assembly", "sequence", "direction") if k in row}
    out[LEVEL[kind]] = row.get(LEVEL[kind], np.nan)
    env_out, flags = _envelope_estimates(env, row, kind, rate_hz_per_s, mass_lbf, eta_max, snr_min_db)
    f_guess = mode_hz if mode_hz else (env_out["f_peak_hz"] if kind == "base" else None)
    tab, fit = _frf_estimates(record, row, kind, f_guess, frf_span)
    eta = env_out.pop("eta_value")
    lo, hi = sorted((float(row["f_start_hz"]), float(row["f_stop_hz"])))
    if fit is not None and ("resonance_outside_band" in flags or not (
            lo + 0.02 * (hi - lo) < fit.f_n_hz < hi - 0.02 * (hi - lo))):
        flags.append("resonance_outside_band")  # a peak at the band's edge is no mode: no FRF read-out
        fit = None
    f_bb, z_bb = _backbone_estimate(tab, fit) if kind == "voltage" else (np.nan, np.nan)
    if kind == "base":
        read = _base_readout(env_out, fit, flags, eta, rate_hz_per_s, eta_frf, frf_misfit)
        sweep = None
    else:
        sweep, why = _sweep_estimate(record, row, kind, fit, env_out, z_bb, (lo, hi), sweep_misfit)
        read = _excited_readout(env_out, fit, sweep, why, flags, kind, f_bb, z_bb, rate_hz_per_s, eta_max,
                                frf_misfit, mass_lbf, record, row)
    f_res, method, eta = read["f_res_hz"], read["f_res_method"], read.get("eta", eta)
    env_out["q_envelope_in"] = env_out["q_in"]  # the envelopes' amplitude at the crossing (or peak)
    env_out["q_in"], env_out["zeta_res"] = read["q_in"], read["zeta_res"]
    env_out["q_peak_in"] = read.get("q_peak_in", env_out.pop("q_peak_env", np.nan))
    env_out.pop("q_peak_env", None)
    if np.isfinite(eta) and eta > eta_max and method != "sweep_fit":  # the sweep fit needs no steady state
        flags.append("eta_high")
    if method == "none" or (method == "peak" and "resonance_outside_band" in flags):
        flags.append("unusable")
    out.update(env_out, f_res_hz=float(f_res), f_res_method=method, eta=float(eta),
               f_frf_hz=fit.f_n_hz if fit else np.nan, f_frf_quad_hz=fit.f_quad_hz if fit else np.nan,
               zeta_frf=fit.zeta if fit else np.nan, f_backbone_hz=float(f_bb), zeta_backbone=float(z_bb),
               f_sweep_hz=sweep.f_hz if sweep else np.nan, zeta_sweep=sweep.zeta if sweep else np.nan,
               sweep_residual=sweep.residual if sweep else np.nan,
               **_modal_constant(sweep),
               frf_residual=fit.residual if fit else np.nan, frf_truncated=fit.truncated if fit else np.nan,
               flags=";".join(dict.fromkeys(flags)))
    return (out, tab) if with_frf else out


READOUT_RULE = (
    "Force- and voltage-driven runs: the swept-mode fit of the whole transient (sweep_fit) wherever it fits "
    "(misfit <= modal.sweep_misfit, damping in (0, 0.5), resonance inside the band and within 5% of the frame it was fitted in, refitted once centred on the mode when the start was 2-20% off): "
    "f_res_hz and zeta_res at q_in, the largest amplitude the fitted response reached. Where it does not fit, "
    "the run is flagged sweep_fit_failed and the whole-record FRF is read instead (frf_backbone for a voltage, "
    "the FRF fit's quadrature for a force, else its pole: frf_fit) at q_in = q_peak_in, the response's "
    "band-limited envelope peak: the amplitude a quasi-steady sweep holds at resonance. That is only true of a "
    "quasi-steady sweep: beyond eta_max the FRF read-out belongs to no known amplitude and the run is also "
    "flagged unusable. Base-driven runs: the lag-corrected quadrature of the envelopes (quadrature, "
    "quadrature_slope beyond eta_max) at the envelopes' amplitude there, or the FRF fit's quadrature beyond "
    "eta_frf (frf_fit), with the phase-resonance damping; the envelope peak (peak) where the phase never "
    "reaches quadrature.")


def _modal_constant(sweep) -> dict:
    """The swept-mode fit's modal constant at its resonance, A(w_r), and its slope dA/dw (per rad/s): the
    columns modal_constant_re/_im, modal_slope_re/_im ((in/s^2) per reference unit; NaN without a fit)."""
    if sweep is None:
        return dict(modal_constant_re=np.nan, modal_constant_im=np.nan, modal_slope_re=np.nan, modal_slope_im=np.nan)
    wr = 2 * np.pi * sweep.f_hz
    a = sweep.modal_constant + sweep.modal_slope * (wr / sweep.w0 - 1.0)
    da = sweep.modal_slope / sweep.w0
    return dict(modal_constant_re=a.real, modal_constant_im=a.imag, modal_slope_re=da.real, modal_slope_im=da.imag)


def readout_rule() -> str:
    """The rule that picks each run's (f_res_hz, zeta_res, q_in), in words (the contract quotes it)."""
    return READOUT_RULE


def _backbone_estimate(tab, fit):
    """A voltage's equal-amplitude pair backbone at the peak (NaN when not this mode or too few levels)."""
    if fit is None:
        return np.nan, np.nan
    f_bb, z_bb, _ = backbone_at_peak(pair_backbone(tab["freq_hz"].to_numpy(), (tab["x_re"] + 1j * tab["x_im"]).to_numpy(),
                                                   f_guess=fit.f_n_hz, near_frac=3 * fit.zeta))
    if not (np.isfinite(f_bb) and abs(f_bb / fit.f_n_hz - 1) <= 3 * fit.zeta and 0 < z_bb < 0.5):
        return np.nan, np.nan
    return float(f_bb), float(z_bb)


def _base_readout(env_out, fit, flags, eta, rate_hz_per_s, eta_frf, frf_misfit):
    """A base-driven run: the envelopes' lag-corrected quadrature, or the FRF fit's beyond eta_frf."""
    f_res, method = env_out["f_res_hz"], env_out["f_res_method"]
    read = dict(f_res_hz=f_res, f_res_method=method, q_in=env_out["q_in"])
    if fit is not None:
        eta = eta if np.isfinite(eta) else rate_hz_per_s / (fit.f_n_hz * fit.zeta) ** 2
        if eta > eta_frf or method in ("peak", "none"):
            quad = np.isfinite(fit.f_quad_hz) and abs(fit.f_quad_hz - fit.f_n_hz) <= fit.zeta * fit.f_n_hz
            read.update(f_res_hz=fit.f_quad_hz if quad else fit.f_n_hz, f_res_method="frf_fit")
            flags[:] = [f for f in flags if f != "no_quadrature"]
            if quad:  # energy balance at the FRF's quadrature: modal constant -G in/g for z / a_base
                env_out["zeta_phase_resonance"] = zeta_at_quadrature(fit) * G / fit.modal_constant
            _frf_flags(fit, flags, frf_misfit)
    read.update(eta=eta, zeta_res=env_out["zeta_phase_resonance"])
    return read


def _frf_flags(fit, flags, frf_misfit):
    if fit.truncated > 0.01:
        flags.append("frf_truncated")
    if fit.residual > frf_misfit:
        flags.append("frf_misfit")


def _excited_readout(env_out, fit, sweep, why, flags, kind, f_bb, z_bb, rate_hz_per_s, eta_max, frf_misfit,
                     mass_lbf, record, row):
    """A force- or voltage-driven run by `READOUT_RULE`."""
    flags[:] = [f for f in flags if f != "no_quadrature"]
    quad = fit is not None and np.isfinite(fit.f_quad_hz) and abs(fit.f_quad_hz - fit.f_n_hz) <= fit.zeta * fit.f_n_hz
    if kind == "force" and quad:  # energy balance at the FRF's quadrature: modal constant G / mass_lbf (1/m)
        env_out["zeta_phase_resonance"] = zeta_at_quadrature(fit) * (G / mass_lbf) / fit.modal_constant
    if sweep is not None:
        q_peak = band_envelope_peak(record, row, kind, sweep.f_hz)
        env_out["sweep_note"] = ""
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
    _frf_flags(fit, flags, frf_misfit)
    eta = rate_hz_per_s / (f_res * zeta) ** 2 if zeta > 0 else np.inf
    if not eta <= eta_max:  # an FRF read-out of a chirp faster than the mode belongs to no known amplitude
        flags.append("unusable")
    q_peak = band_envelope_peak(record, row, kind, f_res)
    return dict(f_res_hz=f_res, f_res_method=method, q_in=q_peak, zeta_res=zeta, q_peak_in=q_peak, eta=eta)


def band_envelope_peak(record: pd.DataFrame | None, row: dict, kind: str, f_hz: float,
                       cutoff: float = 0.45) -> float:
    """The response's band-limited envelope peak near the mode, as a displacement amplitude (in).

    The response acceleration demodulated at f_hz and low-passed at cutoff f_hz
    (`jointcal.sweepfit.baseband`: the mode's passage and ring-down, not the drive far from it
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


def _sweep_estimate(record, row, kind, fit, env_out, z_bb, band, max_residual):
    """The swept-mode fit (`jointcal.sweepfit`) of a force- or voltage-driven run and, when it is not
    used, why: (SweepFit or None, reason). Started from the FRF read-out (else the envelope peak); the
    fit scans its own damping. Not this mode when its misfit exceeds max_residual, its damping lies
    outside (0, 0.5) or its resonance outside the band or more than 5% from the start."""
    if record is None:
        return None, "no record"
    f0 = fit.f_n_hz if fit is not None else env_out["f_peak_hz"]
    if not (np.isfinite(f0) and f0 > 0):
        return None, "no resonance to start from (no FRF peak, no envelope peak)"
    z0 = next((z for z in (z_bb, fit.zeta if fit is not None else np.nan, env_out["zeta_half_power"])
               if np.isfinite(z) and 1e-4 < z < 0.3), 0.01)
    try:
        sw = fit_swept_mode(record[REFERENCE[kind]].to_numpy(float), record[RESPONSE].to_numpy(float),
                            float(row["sample_rate_hz"]), float(f0), float(z0),
                            modal_phase=0.0 if kind == "force" else None)
        if np.isfinite(sw.f_hz) and 0 < sw.zeta < 0.5 and 0.02 < abs(sw.f_hz / f0 - 1) < 0.2:
            f0 = sw.f_hz  # the start was off (an FRF of a bent peak or a fast chirp): again, centred on the mode
            sw = fit_swept_mode(record[REFERENCE[kind]].to_numpy(float), record[RESPONSE].to_numpy(float),
                                float(row["sample_rate_hz"]), float(f0), float(sw.zeta),
                                modal_phase=0.0 if kind == "force" else None)
    except (ValueError, np.linalg.LinAlgError) as exc:
        return None, f"the fit could not run: {exc}"
    lo, hi = band
    if not (np.isfinite(sw.f_hz) and np.isfinite(sw.zeta)):
        return None, "the fit diverged"
    if sw.residual > max_residual:
        return None, f"misfit {sw.residual:.3f} above modal.sweep_misfit {max_residual:g}: not one mode"
    if not 0 < sw.zeta < 0.5:
        return None, f"damping {sw.zeta:.3g} outside (0, 0.5)"
    if not (lo < sw.f_hz < hi and abs(sw.f_hz / f0 - 1) < 0.05):
        return None, f"resonance {sw.f_hz:.4g} Hz outside the band or more than 5% from its frame, {f0:.4g} Hz"
    return sw, ""


def _frf_estimates(record, row, kind, f_guess, span):
    """The whole-record FRF and its single-mode fit; (empty table, None) without a usable record."""
    if record is None or len(record) < 64:
        return pd.DataFrame(), None
    lo, hi = sorted((float(row["f_start_hz"]), float(row["f_stop_hz"])))
    try:
        return record_frf(record[REFERENCE[kind]].to_numpy(float), record[RESPONSE].to_numpy(float),
                          float(row["sample_rate_hz"]), kind, (lo, hi), span=span,
                          f_guess=f_guess if f_guess is not None and np.isfinite(f_guess) else None)
    except (ValueError, np.linalg.LinAlgError):
        return pd.DataFrame(), None


def _envelope_estimates(env, row, kind, rate_hz_per_s, mass_lbf, eta_max, snr_min_db):
    """Resonance and damping from the envelopes (quadrature, lag-corrected; or the peak)."""
    force = kind == "force"
    flags: list[str] = []
    nan = dict(f_res_hz=np.nan, f_crossing_hz=np.nan, f_peak_hz=np.nan, zeta_half_power=np.nan,
               zeta_phase_resonance=np.nan, q_in=np.nan, response_g=np.nan, base_g=np.nan, eta_value=np.nan,
               group_delay_s=np.nan, snr_db=np.nan, h2_ratio=np.nan, h3_ratio=np.nan, f_res_method="none")
    if len(env) == 0:
        return nan, flags
    use = env["drive_on"].to_numpy(bool) & ~env["bad"].to_numpy(bool)
    if env["bad"].any():
        flags.append("bad_samples")
    e = env[use]
    if len(e) < 8:
        return nan, flags
    f = e["f_drive_hz"].to_numpy()
    Rf = (e["ref_re"] + 1j * e["ref_im"]).to_numpy()
    R = (e["resp_re"] + 1j * e["resp_im"]).to_numpy()
    Z = (e["z_re"] + 1j * e["z_im"]).to_numpy()
    sgn = 1.0 if row["f_stop_hz"] > row["f_start_hz"] else -1.0
    # quadrature: z leads the base acceleration (or a_resp leads the force) by +90 deg
    ratio = Z / Rf if not force else R / Rf
    ph = np.unwrap(np.angle(ratio))
    ph += 2 * np.pi * np.round((np.pi / 2 - np.median(ph)) / (2 * np.pi))
    ip = int(np.argmax(np.abs(R)))
    if 0 < ip < len(f) - 1:  # quadratic refinement of the envelope peak
        y0, y1, y2 = np.abs(R[ip - 1:ip + 2])
        den = y0 - 2 * y1 + y2
        d = 0.5 * (y0 - y2) / den if den < 0 else 0.0
        f_peak = f[ip] + d * (f[ip + 1] - f[ip - 1]) / 2
    else:
        f_peak = f[ip]
    # a resonance outside the band shows as a transmissibility peak at the driven span's edge
    # (frames at full drive only: ramps divide a ringing response by a vanishing base)
    full = np.abs(Rf) >= 0.8 * np.median(np.abs(Rf))
    ff = f[full]
    f_T = ff[int(np.argmax(np.abs(R / Rf)[full]))]
    edge = min(f_T - ff.min(), ff.max() - f_T) < 0.02 * (ff.max() - ff.min())
    lo, hi = _half_power(f, np.abs(R), ip)
    zeta_hp = (hi - lo) / (2 * f_peak) if np.isfinite(lo + hi) else np.nan
    if not np.isfinite(zeta_hp):
        flags.append("no_half_power")
    # a drive voltage is not the force: its phase to the response has no quadrature meaning
    cands = _crossing(ph, np.pi / 2) if kind != "voltage" else np.zeros(0, int)
    if cands.size:
        i = cands[np.argmin(np.abs(f[cands] - f_peak))]
        w = (np.pi / 2 - ph[i]) / (ph[i + 1] - ph[i]) if ph[i + 1] != ph[i] else 0.0
        f_x, t_x = _interp(i, w, f, e["time_s"].to_numpy())
        q, a_resp, a_ref = (float(v) for v in _interp(i, w, np.abs(Z), np.abs(R), np.abs(Rf)))
        # group delay from the phase slope over frames within +-zeta f/2 of the crossing
        z_guess = a_ref * G / (2 * (2 * np.pi * f_x) ** 2 * q) if not force else 0.02
        near = np.abs(f - f_x) <= max(0.5 * z_guess * f_x, 2.5 * np.median(np.abs(np.diff(f))))
        slope = np.polyfit(f[near], ph[near], 1)[0] if near.sum() >= 3 else (ph[i + 1] - ph[i]) / (f[i + 1] - f[i])
        tau_g = abs(slope) / (2 * np.pi)
        # the local sweep rate at the crossing (controllers deviate from linear sweeps)
        t_e = e["time_s"].to_numpy()
        local = np.abs(np.gradient(f, t_e)) if len(f) > 2 else np.array([rate_hz_per_s])
        rate = float(np.interp(t_x, t_e, local)) if np.all(np.isfinite(local)) else rate_hz_per_s
        rate = rate if 0 < rate < 10 * rate_hz_per_s else rate_hz_per_s
        # Quasi-steady sweeps lag by the phase relaxation time at fixed amplitude,
        # 1/(zeta omega); the slope seen along the sweep also holds the resonance moving
        # with amplitude (a softening joint's backbone), which overstates the lag. Beyond
        # eta_max the measured zeta is itself corrupted by the transient: use the slope.
        if not force and np.isfinite(z_guess) and z_guess > 0 and rate / (f_x * z_guess) ** 2 <= eta_max:
            tau_g = 1.0 / (2 * np.pi * f_x * z_guess)
            method = "quadrature"
        else:
            method = "quadrature_slope"
        f_res = f_x - sgn * rate * tau_g
    else:
        if kind != "voltage":
            flags.append("no_quadrature")
        f_x, t_x = f_peak, np.nan
        q, a_resp, a_ref = float(np.abs(Z[ip])), float(np.abs(R[ip])), float(np.abs(Rf[ip]))
        f_res, method = f_peak, "peak"
        tau_g = np.nan
    omega = 2 * np.pi * f_res
    if force:
        zeta_pr = a_ref / (2 * (mass_lbf / G) * a_resp * G) if method.startswith("quadrature") else np.nan
    else:
        zeta_pr = a_ref * G / (2 * omega**2 * q) if method.startswith("quadrature") else np.nan
    zeta_eta = zeta_pr if np.isfinite(zeta_pr) else zeta_hp
    eta = rate_hz_per_s / (f_res * zeta_eta) ** 2 if np.isfinite(zeta_eta) and zeta_eta > 0 else np.nan
    if edge and kind == "base":  # an open-loop reference drops out at resonance: the FRF fit checks instead
        flags.append("resonance_outside_band")
    noise = float(np.median(e["noise_g"]))
    snr = 20 * np.log10(a_resp / noise) if noise > 0 else np.inf
    if snr < snr_min_db:
        flags.append("low_snr")
    out = dict(f_res_hz=float(f_res), f_crossing_hz=float(f_x), f_peak_hz=float(f_peak),
               zeta_half_power=float(zeta_hp), zeta_phase_resonance=float(zeta_pr), q_in=float(q),
               response_g=float(a_resp), base_g=float(a_ref) if kind == "base" else np.nan, eta_value=float(eta),
               group_delay_s=float(tau_g), snr_db=float(snr), h2_ratio=float(e["h2_amp_g"].iloc[ip] / abs(R[ip])),
               h3_ratio=float(e["h3_amp_g"].iloc[ip] / abs(R[ip])), f_res_method=method,
               q_peak_env=float(np.abs(Z).max()))
    if kind != "base":
        out[REFERENCE[kind]] = float(a_ref)
    return out, flags


def measure_run(record: pd.DataFrame, row: dict, *, envelopes_kw: dict | None = None,
                modal_kw: dict | None = None):
    """One run from its record to its modal properties: the one record -> envelopes -> modal chain.

    The workflow's envelopes and modal stages, the validation stage (on simulated
    records) and the tests all call this, so that measured and simulated responses go
    through the same window, ridge and estimators.

    Parameters
    ----------
    record : DataFrame
        The run record (columns of the raw-data contract).
    row : mapping
        Its manifest row.
    envelopes_kw, modal_kw : dict, optional
        Keyword options of `jointcal.signal.envelopes` and `modal_properties` (the
        config's ``envelopes`` and ``modal`` sections).

    Returns
    -------
    env : DataFrame
        The envelopes (see `jointcal.signal.envelopes`).
    meta : EnvelopeMeta or None
        None when the record is too short for the envelope window (env is then empty).
    props : dict
        One row of modal_properties.csv.
    """
    try:
        env, meta = envelopes(record, row, **(envelopes_kw or {}))
        rate = meta.rate_hz_per_s
    except ValueError:  # a chirp too short for the envelope window: the FRF path alone
        env, meta, rate = pd.DataFrame(columns=ENVELOPE_COLUMNS), None, float(row["sweep_rate_hz_per_s"])
    props = modal_properties(env, row, rate_hz_per_s=rate, record=record, **(modal_kw or {}))
    return env, meta, props


def scatter(table: pd.DataFrame) -> pd.DataFrame:
    """Scatter of f_res and damping across repeats and up/down pairs, per assembly.

    Rows (assembly, quantity, level, source): 'repeats' for a level run more than twice,
    'up_down' for a level with one up/down pair, and one 'pooled' row per (assembly,
    quantity) with the dof-weighted pooled relative standard deviation (level NaN).
    Rows flagged unusable are left out.
    """
    level = next((c for c in LEVEL.values() if c in table.columns), "level_g")
    ok = ~table["flags"].fillna("").str.contains("unusable")
    rows = []
    for (asm), grp in table[ok].groupby("assembly", sort=False):
        for qty in ("f_res_hz", "zeta_res", "zeta_phase_resonance", "zeta_half_power"):
            if qty not in grp.columns:
                continue
            ss, dof = 0.0, 0
            for lev, g in grp.groupby(level, sort=True):
                v = g[qty].dropna().to_numpy(float)
                if v.size < 2:
                    continue
                sd = float(np.std(v, ddof=1))
                rel = sd / abs(v.mean())
                rows.append(dict(assembly=asm, quantity=qty, level=lev, source="repeats" if v.size > 2 else "up_down",
                                 n=v.size, mean=float(v.mean()), std=sd, rel_std=rel))
                ss += rel**2 * (v.size - 1)
                dof += v.size - 1
            rows.append(dict(assembly=asm, quantity=qty, level=np.nan, source="pooled", n=dof,
                             mean=np.nan, std=np.nan, rel_std=float(np.sqrt(ss / dof)) if dof else np.nan))
    out = pd.DataFrame(rows, columns=["assembly", "quantity", "level", "source", "n", "mean", "std", "rel_std"])
    return out.rename(columns={"level": level})


def run_flags(ingest_flags: str | None, stage_flags: str | None, run_id: str, *,
              sweep_note: str | None = None) -> tuple[str, list[str]]:
    """A run's flags in modal_properties.csv, and a sentence for each that the log shows.

    The ingest stage's flags come first, then this stage's, each once. A run that ingest
    flagged for wrong units, level, channels or clipping (``jointcal._checks.UNUSABLE_FLAGS``)
    is also ``unusable``: no fit reads it.

    Parameters
    ----------
    ingest_flags : str or None
        runs.csv's ``flags`` cell (``;``-separated; empty, None or NaN for none).
    stage_flags : str or None
        The flags `modal_properties` gave the run (``;``-separated).
    run_id : str
        The run, named in the sentences.
    sweep_note : str, optional
        Why the whole-transient fit failed, added to a ``sweep_fit_failed`` sentence.

    Returns
    -------
    flags : str
        ``;``-separated.
    notes : list of str
        ``"<run_id>: <flag>: <what it means>."`` per flag of `FLAG_WORDS` (or with a detail after ``:``),
        after a sentence on a run made unusable by its ingest flags.
    """
    from ._checks import UNUSABLE_FLAGS

    ingest = [f for f in str(ingest_flags or "").split(";") if f and f != "nan"]
    flags = list(dict.fromkeys(ingest + [f for f in str(stage_flags or "").split(";") if f]))
    notes = []
    wrong = [f for f in ingest if f.split(":")[0] in UNUSABLE_FLAGS]
    if wrong and "unusable" not in flags:  # wrong units, level, channels; clipped: no fit
        flags.append("unusable")
        notes.append(f"{run_id}: unusable: ingest flagged {', '.join(wrong)} (see the ingest log); "
                     "left out of the calibration")
    for flag in [f for f in flags if f.split(":")[0] in FLAG_WORDS or ":" in f]:
        why = f" ({sweep_note})" if flag == "sweep_fit_failed" and sweep_note else ""
        notes.append(f"{run_id}: {flag.split(':')[0]}: {FLAG_WORDS.get(flag.split(':')[0], flag)}{why}.")
    return ";".join(flags), notes
