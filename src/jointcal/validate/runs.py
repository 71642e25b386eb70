"""One run simulated with a model driven by its measured reference record, and compared with the measurement.

The simulated record keeps the measured reference channel exactly as recorded (NaN, DC
offset and all) and replaces the response channel by the model's, so
`jointcal.measure.modal.measure_run` sees the same reference channel: the same drive ridge, frames,
window and estimators for both records, and the processing bias cancels. The model is
driven by the reference cleaned as `jointcal.measure.envelopes.envelopes` cleans it (NaN gaps bridged
linearly here, since the integrator needs a finite input; median removed):

* base-driven (the Ministack): the base acceleration itself;
* force- and voltage-driven (one mode, `jointcal.calibrate.kind`): the modal force per unit
  modal mass A(w) r(t), the reference through the run's modal constant, a gain of the drive
  frequency A(w) = A_c + A' (w - w_c) (held beyond +-45% of w_c) applied line by line to the
  record's spectrum: 1/m for a force at the driving point; for an amplifier voltage the
  rig's electrical and residual dynamics in one complex, frequency-sloped gain, measured by
  the swept-mode fits (`jointcal.measure.sweepfit`; the campaign's median, ``drive_gain`` in the
  row). The calibrated mode (the rig's, back-EMF damping included) responds to it as to a
  base acceleration -A r on a fixed base, and its acceleration is that response's.

`draw_transmissibility` is the cheaper path for posterior draws (the predictive band
only, never E): it simulates only the frames of the band (plus a tapered lead-in) and
demodulates both channels with the drive phase rebuilt from the measured frames'
drive frequencies and the same Hann window (tested against `measure_run` to 0.02 dB and
0.1 deg).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.signal.windows import hann

from ..io.contract import LEVEL, REFERENCE, UNUSABLE, excitation_kind, level_column
from ..measure.modal import measure_run
from ..measure.peaks import FULL_DRIVE, transmissibility
from ..measure.peaks import full_drive as full_drive_frames
from ..models import MinistackModel, simulate
from .drive import clean_base, drive_gain, model_input, reference_column, simulate_record

__all__ = ["clean_base", "reference_column", "drive_gain", "model_input", "simulate_record", "band_frames",
           "compare_run", "measure_pair", "time_envelopes", "draw_transmissibility"]


HEAD = ("run_id", "assembly", "sequence", *LEVEL.values(), "direction", "sweep_rate_hz_per_s")


def run_head(row: Mapping) -> dict:
    """A run's identity for the tables: run_id, assembly, sequence, its level column, direction, sweep rate
    (when the row has it), and ``level``, the level in its own unit (g, lbf or V) whatever the reference."""
    head = {k: row[k] for k in HEAD if k in row}
    head["level"] = float(row[level_column(row)]) if level_column(row) else np.nan
    return head


def band_frames(env: pd.DataFrame, f_res_hz: float, band: Sequence[float], *,
                full_drive: float = 0.8) -> NDArray[np.bool_]:
    """Frames compared: drive on, not bad, at full drive (|reference| >= full_drive x median), f in band x f_res.

    full_drive 0.8 leaves out a controlled drive's ramps (a ringing response over a vanishing
    base); an open-loop force drops out at resonance by physics, and takes 0.05.
    """
    f = env["f_drive_hz"].to_numpy()
    return full_drive_frames(env, full_drive) & (f >= band[0] * f_res_hz) & (f <= band[1] * f_res_hz)


def _on_grid(f_src: NDArray, T: NDArray, f_dst: NDArray) -> NDArray[np.complex128]:
    """Complex T(f) interpolated as log-magnitude and unwrapped phase (sorted by f)."""
    o = np.argsort(f_src, kind="stable")
    lm = np.interp(f_dst, f_src[o], np.log(np.abs(T[o])))
    ph = np.interp(f_dst, f_src[o], np.unwrap(np.angle(T[o])))
    return np.exp(lm + 1j * ph)


def _phase_deg(T: NDArray) -> NDArray[np.float64]:
    """Unwrapped phase (deg) along the frames, anchored so the first frame lies in (-180, 180]."""
    ph = np.degrees(np.unwrap(np.angle(T)))
    return ph - 360.0 * np.round(ph[0] / 360.0) if ph.size else ph


def full_drive_fraction(props: Mapping) -> float:
    """`band_frames`' full-drive fraction for a run: 0.05 for a force reference, else 0.8."""
    return 0.05 if excitation_kind(props) == "force" else FULL_DRIVE


def compare_run(env_m: pd.DataFrame, props_m: Mapping, env_s: pd.DataFrame, props_s: Mapping, *,
                band: Sequence[float] = (0.8, 1.2), zeta_key: str = "zeta_res"
                ) -> tuple[pd.DataFrame, dict]:
    """Measured vs simulated envelope of one run, frame by frame, and the run's metrics.

    Parameters
    ----------
    env_m, env_s : DataFrame
        Envelopes of the measured and simulated records (`jointcal.measure.envelopes.envelopes`).
    props_m, props_s : mapping
        Their modal rows (`jointcal.measure.modal.modal_properties`).
    band : (lo, hi)
        Compared band as fractions of the measured resonance frequency f_res_hz.
    zeta_key : str
        Damping column compared.

    Returns
    -------
    frames : DataFrame, one row per measured frame that is drive-on, not bad and at full drive
        time_s, f_hz, mag_meas_db, phase_meas_deg, mag_sim_db, phase_sim_deg (of the
        transmissibility response/base), d_mag_db, d_phase_deg (simulated minus measured),
        resp_meas_g, resp_sim_g (response envelope), in_band, band_lo_hz, band_hi_hz.
    metrics : dict
        One row of metrics.csv (errors in dB, deg, and relative for f_res and zeta).
    """
    f_res = float(props_m["f_res_hz"])
    head = run_head(props_m)
    fd = full_drive_fraction(props_m)
    if not np.isfinite(f_res) or UNUSABLE in str(props_m.get("flags", "")):
        return pd.DataFrame(), {**head, "n_frames": 0, "note": "measured run unusable"}
    lo, hi = band[0] * f_res, band[1] * f_res
    use_m = band_frames(env_m, f_res, (0.0, np.inf), full_drive=fd)
    use_s = band_frames(env_s, f_res, (0.0, np.inf), full_drive=fd)
    f = env_m["f_drive_hz"].to_numpy()[use_m]
    T_m = transmissibility(env_m)[use_m]
    f_s = env_s["f_drive_hz"].to_numpy()[use_s]
    T_s = _on_grid(f_s, transmissibility(env_s)[use_s], f)
    R_s = _on_grid(f_s, (env_s["resp_re"] + 1j * env_s["resp_im"]).to_numpy()[use_s], f)
    inside = (f >= min(f_s, default=np.inf)) & (f <= max(f_s, default=-np.inf))
    d = T_s / T_m
    ph_m = _phase_deg(T_m)
    d_ph = np.degrees(np.angle(d))  # wrapped to (-180, 180]
    frames = pd.DataFrame(dict(
        time_s=env_m["time_s"].to_numpy()[use_m], f_hz=f, mag_meas_db=20 * np.log10(np.abs(T_m)),
        phase_meas_deg=ph_m, mag_sim_db=20 * np.log10(np.abs(T_s)), phase_sim_deg=ph_m + d_ph,
        d_mag_db=20 * np.log10(np.abs(d)), d_phase_deg=d_ph,
        resp_meas_g=np.abs((env_m["resp_re"] + 1j * env_m["resp_im"]).to_numpy()[use_m]), resp_sim_g=np.abs(R_s),
        in_band=(f >= lo) & (f <= hi) & inside, band_lo_hz=lo, band_hi_hz=hi))
    b = frames[frames["in_band"]]
    below = frames[(frames["f_hz"] < 0.7 * f_res) & inside]
    zm, zs = float(props_m.get(zeta_key, np.nan)), float(props_s.get(zeta_key, np.nan))
    x = (b["f_hz"] / f_res - 1.0) / zm  # distance from resonance in half-power half-widths
    flank_lo, flank_hi = b[(x >= -3) & (x <= -1)], b[(x >= 1) & (x <= 3)]
    peak_m = float(b["resp_meas_g"].max()) if len(b) else np.nan
    peak_s = float(b["resp_sim_g"].max()) if len(b) else np.nan
    metrics = {**head, "n_frames": int(len(b)), "band_lo_hz": lo, "band_hi_hz": hi,
               "mag_err_rms_db": float(np.sqrt(np.mean(b["d_mag_db"] ** 2))) if len(b) else np.nan,
               "mag_err_mean_db": float(b["d_mag_db"].mean()) if len(b) else np.nan,
               "phase_err_rms_deg": float(np.sqrt(np.mean(b["d_phase_deg"] ** 2))) if len(b) else np.nan,
               "phase_err_mean_deg": float(b["d_phase_deg"].mean()) if len(b) else np.nan,
               "peak_meas_g": peak_m, "peak_sim_g": peak_s, "peak_ratio": peak_s / peak_m,
               "f_res_meas_hz": f_res, "f_res_sim_hz": float(props_s["f_res_hz"]),
               "f_res_rel_err": float(props_s["f_res_hz"]) / f_res - 1.0,
               "zeta_meas": zm, "zeta_sim": zs, "zeta_rel_err": zs / zm - 1.0,
               "flank_below_ratio": float(10 ** (flank_lo["d_mag_db"].median() / 20)) if len(flank_lo) else np.nan,
               "flank_above_ratio": float(10 ** (flank_hi["d_mag_db"].median() / 20)) if len(flank_hi) else np.nan,
               "low_freq_ratio": float(10 ** (below["d_mag_db"].median() / 20)) if len(below) else np.nan,
               "flags_meas": props_m.get("flags", ""), "flags_sim": props_s.get("flags", ""), "note": ""}
    return frames, metrics


def measure_pair(model: MinistackModel, record: pd.DataFrame, row: Mapping, measured: tuple | None = None, *,
                 envelopes_kw: dict | None = None, modal_kw: dict | None = None, with_record: bool = False):
    """measure_run on the measured record (unless given) and on the model's record: ((env, meta, props) x 2)
    (and the model's record, with ``with_record``). A row's ``mode_hz`` (the frequency the modal stage read
    the run's mode at, `jointcal.measure.campaign`) overrides the modal options' for both."""
    if row.get("mode_hz") is not None and np.isfinite(row["mode_hz"]):
        modal_kw = {**(modal_kw or {}), "mode_hz": float(row["mode_hz"])}
    meas = measured if measured is not None else measure_run(record, dict(row), envelopes_kw=envelopes_kw,
                                                             modal_kw=modal_kw)
    sim_record = simulate_record(model, record, row)
    sim = measure_run(sim_record, dict(row), envelopes_kw=envelopes_kw, modal_kw=modal_kw)
    return (meas, sim, sim_record) if with_record else (meas, sim)


def time_envelopes(record: pd.DataFrame, sim_record: pd.DataFrame, f_hz: float, fs: float, *,
                   n_max: int = 2000) -> pd.DataFrame:
    """Measured and simulated response envelopes in time near the mode (g), for transients.

    A chirp faster than the mode (or its free decay) is not a sequence of steady states, and
    the drive-frequency frames hold few points near resonance; the response's band-limited
    envelope (`jointcal.measure.sweepfit.baseband` at f_hz, low-passed at 0.45 f_hz) shows the passage
    and the ring-down as they were. Columns time_s, resp_meas_g, resp_sim_g; at most n_max rows.
    """
    from ..measure.sweepfit import baseband

    out = {}
    for name, rec in (("meas", record), ("sim", sim_record)):
        a = rec["response_accel_g"].to_numpy(float)
        good = np.isfinite(a)
        a = np.where(good, a - np.median(a[good]), 0.0)
        env = np.abs(baseband(a, fs, 2 * np.pi * f_hz, 0.45 * f_hz))
        env[~good] = np.nan
        out[f"resp_{name}_g"] = env
    step = max(1, len(record) // n_max)
    return pd.DataFrame({"time_s": record["time_s"].to_numpy(float)[::step],
                         **{k: v[::step] for k, v in out.items()}})


def draw_transmissibility(models: Sequence[MinistackModel], record: pd.DataFrame, env_m: pd.DataFrame,
                          meta, frames: NDArray[np.bool_], *, lead_s: float = 0.1,
                          meta_row: Mapping | None = None) -> NDArray[np.complex128]:
    """Transmissibility response/reference of many models on the measured frames `frames` (the cheap path).

    Parameters
    ----------
    models : sequence of MinistackModel, length P
    record : DataFrame
        The measured run record.
    env_m : DataFrame
        Its envelopes; ``meta`` their `EnvelopeMeta` (window, hop, sample rate).
    frames : ndarray of bool, shape (n_frames,)
        Frames wanted (a contiguous stretch, e.g. the band).
    lead_s : float
        Simulated time before the first frame's window, s; the input rises over its
        first half with a raised cosine, so the start-up transient has died out.
    meta_row : mapping, optional
        The run's row, for a force or voltage reference's ``drive_gain`` (`model_input`).

    Returns
    -------
    ndarray, complex, shape (P, frames.sum())
    """
    idx = np.flatnonzero(frames)
    if idx.size == 0:
        return np.zeros((len(models), 0), complex)
    fs, n, hop = meta.fs_hz, meta.n_window, int(round(meta.hop_s * meta.fs_hz))
    base, col = model_input(record, {"sample_rate_hz": fs, **(meta_row or {})})
    ref = base if col == REFERENCE["base"] else clean_base(record, col)
    lead = int(round(lead_s * fs))
    s0 = max(0, hop * idx[0] - lead)
    s1 = min(base.size, hop * idx[-1] + n)
    x = base[s0:s1].copy()
    xr = ref[s0:s1].copy()
    ramp = min(lead // 2, hop * idx[0] - s0)
    if ramp > 1 and s0 > 0:
        taper = 0.5 * (1 - np.cos(np.pi * np.arange(ramp) / ramp))
        x[:ramp] *= taper
        xr[:ramp] *= taper
    t = (s0 + np.arange(x.size)) / fs
    f_s = np.interp(t, env_m["time_s"].to_numpy(), env_m["f_drive_hz"].to_numpy())
    carrier = np.exp(-2j * np.pi * np.cumsum(f_s) / fs)
    win = hann(n, sym=False)
    starts = hop * idx - s0
    rows = starts[:, None] + np.arange(n)
    B = (xr * carrier)[rows] @ win
    out = np.empty((len(models), idx.size), complex)
    for i, model in enumerate(models):
        y = simulate(model, x, fs).response_g
        if col != REFERENCE["base"]:
            y = y - x
        out[i] = ((y * carrier)[rows] @ win) / B
    return out
