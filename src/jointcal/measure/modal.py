"""Measured modal properties of one run: resonance, damping, amplitude and quality flags.

From a run's envelopes (`jointcal.measure.envelopes`) and its record, by the rule
`READOUT_RULE` states (one row of modal_properties.csv):

* base-driven runs: resonance where the relative displacement z is in quadrature with
  the base acceleration (z leads a_base by 90 deg), corrected for the sweep's lag: a
  sweep at rate r shows the steady-state phase delayed by the group delay tau_g, so
  f_res = f_crossing - sgn(r) r tau_g (first order in eta; docs/physics.md, "Swept-sine
  lag"). For quasi-steady sweeps (eta <= eta_max) tau_g = 1/(zeta omega) with the
  phase-resonance zeta (method 'quadrature'); beyond, the measured phase slope (method
  'quadrature_slope'); beyond eta_frf the whole-record FRF's single-mode fit (method
  'frf_fit', `jointcal.measure.frf`). Steps in `jointcal.measure._envelope_readout`.
* force- and amplifier-voltage-driven runs (an open-loop shaker: the force drops out at
  resonance, the voltage is not the force, chirps are often fast): one mode with
  amplitude-dependent frequency and damping driven by the measured reference, fitted to
  the whole transient (`jointcal.measure.sweepfit`, method 'sweep_fit'), at the largest
  amplitude the run reached, which becomes q_in (the envelopes' own amplitude stays in
  q_envelope_in). Kept only when it is this mode (misfit <= modal.sweep_misfit, resonance
  within SWEEP_FRAME of the frequency it was fitted in); else the whole-record FRF
  (`jointcal.measure.frf`; for a voltage the equal-amplitude line pairs,
  `jointcal.measure.backbone`). Steps in `jointcal.measure._excited`.
* every run with a record also gets the FRF read-out (f_frf_hz, zeta_frf, frf_residual),
  the envelope peak (the paper's resonance read-out), the half-power damping of the
  response envelope (the paper's estimate) and the phase-resonance energy balance at
  quadrature, zeta = |a_base| / (2 omega^2 q) (force-driven: zeta = |F| / (2 m |a|), which
  needs the moving mass; voltage-driven: none);
* quality flags (`FLAG_WORDS`); a flagged value is kept and marked, never dropped.
  'unusable' marks a row the calibration must not use.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..io.contract import LEVEL, REFERENCE, RESPONSE, UNUSABLE, excitation_kind
from ..units import G
from ._envelope_readout import EDGE, envelope_estimates
from ._excited import REFIT, SWEEP_FRAME, ZETA_MAX, backbone_estimate, excited_readout, modal_constant, sweep_estimate
from .envelopes import ENVELOPE_COLUMNS, envelopes
from .frf import ModeFit, frf_flags, quadrature_ok, record_frf, zeta_at_quadrature
from .sweepfit import WINDOW

__all__ = ["modal_properties", "measure_run", "READOUT_RULE", "FLAG_WORDS", "ENVELOPE_COLUMNS"]


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
    "sweep_truncated": f"the record ends with the response still over the fitted window's level ({WINDOW:.0%} of "
                       "its peak): the free decay that fixes the damping is cut (a real beam record cut 0.5 s after "
                       "its peak: zeta +1..+11%); record until the response has died out",
    "sweep_fit_failed": "the whole-transient fit of one mode did not fit (sweep_note says why); the FRF read-out "
                        "is reported at the band-limited envelope peak, usable only for a quasi-steady sweep",
    "units": "the response/base ratio below resonance says the response is in other units than its column "
             "name (ingest's check); the run is left out",
    "no_mode": "the run's band holds none of the modes found in its assembly's runs (jointcal.measure.modes)",
    "dead": "the response does not respond to the drive (an offset and noise: a dead or unplugged sensor; "
            "ingest's check); the run is left out",
    "shaker_on": "the force gauge goes on reading after the drive's cut (a shaker left attached): the free decay "
                 "is the structure's and the shaker's armature's together (on a virtual 1 lbf beam with a 0.05 lbf "
                 "armature it rang 2.4% low), and no swept run of the mode measured the modal constant that reads "
                 "the structure's own through the force; sweep the mode too, cut the stinger or ring the structure "
                 "down by an impact",
    "through_force": "the force gauge goes on reading after the drive's cut (a shaker left attached): the decay "
                     "was read through the measured force (jointcal.measure.forced_decay), the structure's own f "
                     "and zeta, with the modal constant and residual receptance of the mode's lowest-level sweep",
    UNUSABLE: "no resonance could be estimated from this run",
}


def modal_properties(env: pd.DataFrame, row: dict, *, rate_hz_per_s: float, mass_lbf: float = 2.65,
                     eta_max: float = 0.5, eta_frf: float = 4.0, snr_min_db: float = 20.0, frf_span: float = 2.0,
                     frf_misfit: float = 0.02, sweep_misfit: float = 0.1, mode_hz: float | None = None,
                     record: pd.DataFrame | None = None, with_frf: bool = False, coil=None):
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
        Half-width of the FRF fit band in half-power bandwidths (`jointcal.measure.frf.fit_mode`).
    frf_misfit : float
        Relative RMS residual of the FRF fit above which the run is flagged 'frf_misfit'
        when an FRF read-out is reported (measured on synthetic rigs,
        tests/benchmarks/accept_rigs.py: a linear mode with 0.3% noise fits to 0.07-0.14%,
        a lightly nonlinear 100 Hz jointed beam to 0.4-1.8%, the Table 3.2 joint's bent
        peaks to 1.1-9%, its eta-20 chirps' transients to 9-63%).
    sweep_misfit : float
        Relative RMS misfit of the swept-mode fit above which it is not this mode
        (`jointcal.measure.sweepfit`; measured 0.0002-0.02 on synthetic rigs with 0.3-2% noise,
        0.016-0.017 on the real UNESP beam records).
    mode_hz : float, optional
        Approximate natural frequency (Hz) of the mode to read where the band holds more
        than one: the FRF peak nearest it (`jointcal.measure.campaign` gives each mode's peak
        in the run, found by `jointcal.measure.modes`). Default: for force- and voltage-driven runs the
        largest peak of the displacement ratio (response / reference / w^2) in the band (a
        higher mode's acceleration peak can be the larger), for base-driven runs the
        envelope peak.
    record : DataFrame, optional
        The raw record, for the whole-record FRF (`jointcal.measure.frf`) and the swept-mode fit.
    with_frf : bool
        Also return the FRF table (H1, H2, coherence, fitted displacement ratio).
    coil : 'fit', (w_e, g) or None
        A voltage drive's coil in the swept-mode fit (`jointcal.measure.sweepfit.fit_swept_mode`): fitted,
        held at its corner (rad/s) and back-EMF gain (1/s^2), or left out; ignored for other drives.

    Returns
    -------
    props : dict
        One row of modal_properties.csv: ``f_res_hz``, ``zeta_res`` and ``q_in`` read by
        the rule of `READOUT_RULE` (``f_res_method`` names it), every estimator's own
        columns beside them, ``q_peak_in`` (the response's band-limited envelope peak near
        the mode, the check of q_in) and ``flags``.
    frf : DataFrame (only with ``with_frf``)
        `jointcal.measure.frf.record_frf`'s table, or an empty one.
    """
    kind = excitation_kind([*(record.columns if record is not None else []), *row])
    env_out, flags = envelope_estimates(env, row, kind, rate_hz_per_s, mass_lbf, eta_max, snr_min_db)
    f_guess = mode_hz if mode_hz else (env_out["f_peak_hz"] if kind == "base" else None)
    tab, fit = _frf_estimates(record, row, kind, f_guess, frf_span)
    band = sorted((float(row["f_start_hz"]), float(row["f_stop_hz"])))
    fit = _mode_in_band(fit, band, flags)
    eta = env_out.pop("eta_value")
    f_bb, z_bb = backbone_estimate(tab, fit) if kind == "voltage" else (np.nan, np.nan)
    if kind == "base":
        read = _base_readout(env_out, fit, flags, eta, rate_hz_per_s, eta_frf, frf_misfit)
        sweep = None
    else:
        sweep, why = sweep_estimate(record, row, kind, fit, env_out, z_bb, band, sweep_misfit, coil)
        read = excited_readout(env_out, fit, sweep, why, flags, kind, f_bb, z_bb, rate_hz_per_s, eta_max,
                               frf_misfit, mass_lbf, record, row)
    out = _table_row(row, kind, env_out, read, read.get("eta", eta), eta_max, flags)
    out.update(f_frf_hz=fit.f_n_hz if fit else np.nan, f_frf_quad_hz=fit.f_quad_hz if fit else np.nan,
               zeta_frf=fit.zeta if fit else np.nan, f_backbone_hz=float(f_bb), zeta_backbone=float(z_bb),
               f_sweep_hz=sweep.f_hz if sweep else np.nan, zeta_sweep=sweep.zeta if sweep else np.nan,
               sweep_residual=sweep.residual if sweep else np.nan, **modal_constant(sweep),
               **({"coil_w_e_rad_s": sweep.coil[0], "coil_g_per_s2": sweep.coil[1]} if sweep and sweep.coil else {}),
               frf_residual=fit.residual if fit else np.nan, frf_truncated=fit.truncated if fit else np.nan,
               flags=";".join(dict.fromkeys(flags)))
    return (out, tab) if with_frf else out


def _mode_in_band(fit: ModeFit | None, band: list[float], flags: list[str]) -> ModeFit | None:
    """The FRF fit, or None (flag 'resonance_outside_band') when its peak sits at the band's edge: no mode."""
    lo, hi = band
    if fit is not None and ("resonance_outside_band" in flags or not (
            lo + EDGE * (hi - lo) < fit.f_n_hz < hi - EDGE * (hi - lo))):
        flags.append("resonance_outside_band")
        return None
    return fit


def _table_row(row: dict, kind: str, env_out: dict, read: dict, eta: float, eta_max: float,
               flags: list[str]) -> dict:
    """The row's identity, the envelope columns and the read-out chosen, with the flags eta and the method raise."""
    out = {k: row[k] for k in ("run_id", "assembly", "sequence", "direction") if k in row}
    out[LEVEL[kind]] = row.get(LEVEL[kind], np.nan)
    f_res, method = read["f_res_hz"], read["f_res_method"]
    env_out["q_envelope_in"] = env_out["q_in"]  # the envelopes' amplitude at the crossing (or peak)
    env_out["q_in"], env_out["zeta_res"] = read["q_in"], read["zeta_res"]
    env_out["q_peak_in"] = read.get("q_peak_in", env_out.pop("q_peak_env", np.nan))
    env_out.pop("q_peak_env", None)
    if np.isfinite(eta) and eta > eta_max and method != "sweep_fit":  # the sweep fit needs no steady state
        flags.append("eta_high")
    if method == "none" or (method == "peak" and "resonance_outside_band" in flags):
        flags.append(UNUSABLE)
    out.update(env_out, f_res_hz=float(f_res), f_res_method=method, eta=float(eta))
    return out


# the rule that picks each run's (f_res_hz, zeta_res, q_in), in words (raw_data/README.md quotes it)
READOUT_RULE = (
    "Force- and voltage-driven runs: the swept-mode fit of the whole transient (sweep_fit) wherever it fits "
    f"(misfit <= modal.sweep_misfit, damping in (0, {ZETA_MAX:g}), resonance inside the band and within "
    f"{SWEEP_FRAME:.0%} of the frame it was fitted in, refitted once centred on the mode when the start was "
    f"{100 * REFIT[0]:g}-{REFIT[1]:.0%} off): "
    "f_res_hz and zeta_res at q_in, the largest amplitude the fitted response reached. Where it does not fit, "
    "the run is flagged sweep_fit_failed and the whole-record FRF is read instead (frf_backbone for a voltage, "
    "the FRF fit's quadrature for a force, else its pole: frf_fit) at q_in = q_peak_in, the response's "
    "band-limited envelope peak: the amplitude a quasi-steady sweep holds at resonance. That is only true of a "
    "quasi-steady sweep: beyond eta_max the FRF read-out belongs to no known amplitude and the run is also "
    "flagged unusable. Base-driven runs: the lag-corrected quadrature of the envelopes (quadrature, "
    "quadrature_slope beyond eta_max) at the envelopes' amplitude there, or the FRF fit's quadrature beyond "
    "eta_frf (frf_fit), with the phase-resonance damping; the envelope peak (peak) where the phase never "
    "reaches quadrature.")


def _base_readout(env_out, fit, flags, eta, rate_hz_per_s, eta_frf, frf_misfit):
    """A base-driven run: the envelopes' lag-corrected quadrature, or the FRF fit's beyond eta_frf."""
    f_res, method = env_out["f_res_hz"], env_out["f_res_method"]
    read = dict(f_res_hz=f_res, f_res_method=method, q_in=env_out["q_in"])
    if fit is not None:
        eta = eta if np.isfinite(eta) else rate_hz_per_s / (fit.f_n_hz * fit.zeta) ** 2
        if eta > eta_frf or method in ("peak", "none"):
            quad = quadrature_ok(fit)
            read.update(f_res_hz=fit.f_quad_hz if quad else fit.f_n_hz, f_res_method="frf_fit")
            flags[:] = [f for f in flags if f != "no_quadrature"]
            if quad:  # energy balance at the FRF's quadrature: modal constant -G in/g for z / a_base
                env_out["zeta_phase_resonance"] = zeta_at_quadrature(fit) * G / fit.modal_constant
            frf_flags(fit, flags, frf_misfit)
    read.update(eta=eta, zeta_res=env_out["zeta_phase_resonance"])
    return read


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


def measure_run(record: pd.DataFrame, row: dict, *, envelopes_kw: dict | None = None,
                modal_kw: dict | None = None):
    """One run from its record to its modal properties: the one record -> envelopes -> modal chain.

    The validation stage (on measured and simulated records) and the tests call this; the
    workflow runs the same two steps as two rules (``envelopes_run``: `envelopes`; then
    ``modal_properties``: `modal_properties` with the envelopes' measured sweep rate, or the
    manifest's when the record is too short for the window), with the same options, so that
    measured and simulated responses go through the same window, ridge and estimators.

    Parameters
    ----------
    record : DataFrame
        The run record (columns of the raw-data contract).
    row : mapping
        Its manifest row.
    envelopes_kw, modal_kw : dict, optional
        Keyword options of `jointcal.measure.envelopes.envelopes` and `modal_properties` (the
        config's ``envelopes`` and ``modal`` sections; the section's ``coil`` switch, which
        `jointcal.measure.campaign` acts on across a campaign's runs, is left out: one run is read
        without a coil).

    Returns
    -------
    env : DataFrame
        The envelopes (see `jointcal.measure.envelopes.envelopes`).
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
    kw = dict(modal_kw or {})
    if isinstance(kw.get("coil"), bool):  # the config's switch: the campaign's (measure.campaign), not one run's
        kw.pop("coil")
    props = modal_properties(env, row, rate_hz_per_s=rate, record=record, **kw)
    return env, meta, props


