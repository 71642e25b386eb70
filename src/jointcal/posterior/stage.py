"""The posterior stage on files: start at the GA optimum, run emcee with checkpoints, write summaries.

Outputs in ``out_dir`` (all written atomically):

* ``summary.csv`` -- `jointcal.posterior.summary.summarize` (param, unit, median, q05,
  q95, tau, n_eff, prior_lo, prior_hi, width_ratio, constrained);
* ``chain.npz`` -- ``chain`` (steps, walkers, 8) in the sampler coordinates ``names``,
  ``log_prob`` (steps, walkers), ``samples`` (draws, 8): burned-in, thinned draws of
  (Fs, KT, chi, beta, k, zeta_v, sigma_f, sigma_zeta) in physical units (``sample_names``),
  ``tau_history`` (chunks, 1 + n): chain length then tau, ``q_ref`` (in), ``burn``,
  ``converged``, ``stop_reason`` ("converged", "max_steps" or "projected"),
  ``projected_steps``, ``sample_mode`` (the separated mode of each draw, 0 = heaviest,
  `jointcal.posterior.modes`), ``fit_ratio`` (rms relative residuals of the GA optimum
  over the noise scales, frequency and damping), ``fit_chi2``, ``fit_dof``, ``fit_p`` (its
  chi-square test against them, `fit_test`), ``noise_source`` (where each scale came from:
  'repeats', 'own' or 'floor', `jointcal.posterior.noise`) and emcee's RandomState (``rs_*``);
* ``constraints.txt`` -- convergence (and why the chain stopped), the fit of the optimum
  against the repeat scatter, the modes, then one sentence per parameter and correlation;
* ``predictive.csv`` -- q_in, f_q05, f_q50, f_q95, zeta_q05, zeta_q50, zeta_q95.

The checkpoint (the same arrays, rewritten after every chunk) lives outside the declared
outputs, which Snakemake deletes before a rerun; it carries a fingerprint of the data,
the GA optimum and the settings that shape the chain, and is ignored when they differ.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..calibrate.data import CalibrationInputError, ModalData, read_modal, read_table
from ..calibrate.kind import model_words
from ..calibrate.settings import CalibrateSettings
from ..io import write_bytes_atomic, write_csv_atomic
from .likelihood import LogPosterior
from .modes import find_modes, mode_labels, modes_text
from .fit import P_REJECT, fit_test, goodness_of_fit
from .noise import data_problem, noise_scale
from .sampler import ChainResult, random_state_arrays, random_state_tuple, run_chain
from .settings import PosteriorSettings
from .summary import burn_in, constraints_text, predictive_band, summarize

__all__ = ["OUTPUTS", "OBSERVED", "P_REJECT", "start_ball", "run_posterior", "posterior_of", "goodness_of_fit",
           "fit_test"]

OUTPUTS = ("summary.csv", "chain.npz", "constraints.txt", "predictive.csv")
OBSERVED = ("Fs", "KT", "beta", "k")  # parameters whose own tau also counts in the stopping rule (y mixes them)


def start_ball(lp: LogPosterior, theta: np.ndarray, ps: PosteriorSettings) -> np.ndarray:
    """Walkers (n_walkers, ndim) in sampler coordinates: a small ball around the GA optimum, inside the bounds."""
    x = lp.space.to_unit(theta) * (lp.space.x_hi - lp.space.x_lo) + lp.space.x_lo
    r_f, r_z = lp.residuals(x[None])
    noise = np.log10([np.sqrt(np.mean(r_f**2)), np.sqrt(np.mean(r_z**2))])
    x = np.r_[x, noise]
    width = lp.upper - lp.lower
    margin = 3.0 * ps.ball * width  # a centre on a bound (e.g. beta at its floor) moves in, so no walker is clipped
    x = np.clip(np.where(np.isfinite(x), x, lp.lower), lp.lower + margin, lp.upper - margin)
    rng = np.random.default_rng(ps.seed)
    x0 = x + ps.ball * width * rng.standard_normal((ps.n_walkers, lp.ndim))
    x0 = np.clip(x0, lp.lower + 1e-9 * width, lp.upper - 1e-9 * width)
    return lp.to_y(x0)


def _npz(arrays: dict) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _read(modal_csv, scatter_csv, ga_best_json, assembly: str, cal: CalibrateSettings, ps: PosteriorSettings,
          backbone_csv=None) -> tuple[ModalData, dict, CalibrateSettings, np.ndarray, list[str], tuple[str, str]]:
    """Step 1, read: the assembly's modal data with its noise scales (`noise_scale`), the calibration's
    optimum and the settings it was made with (with backbone.csv: a ring-down's windows and a level's
    dwells' phase resonance, each read-out weighted once, as the calibration read them)."""
    data = read_modal(modal_csv, assembly, scatter_csv=scatter_csv, damping=cal.damping,  # type: ignore[arg-type]
                      floors=dict(ps.rel_std_floor), backbone_csv=backbone_csv)
    data, sources, own = noise_scale(data, read_table(scatter_csv), dict(ps.rel_std_floor))
    best = json.loads(Path(ga_best_json).read_text())
    cal = cal.resolved(best)  # the model kind, mass and bounds the calibration used
    for key in ("model", "viscous", "damping"):
        if best.get(key) != getattr(cal, key):
            raise CalibrationInputError(f"{ga_best_json}: it was calibrated with {key} {best.get(key)!r}, "
                                        f"the config now says {getattr(cal, key)!r}; rerun the calibrate stage.")
    return data, best, cal, cal.space.vector(best), [*data.notes, *own], sources


def posterior_of(modal_csv, scatter_csv, ga_best_json, assembly: str, cal: CalibrateSettings, ps: PosteriorSettings,
                 backbone_csv=None) -> tuple[LogPosterior, dict, CalibrateSettings, np.ndarray, list[str], tuple[str, str]]:
    """The log-posterior the chain samples, without sampling: read (`_read`), stop on what in the data makes it
    meaningless (`data_problem`: two modes, noise above noise_max), and build it. `fit_test` of it at the
    returned optimum is the chi-square the verdict shows.

    Returns
    -------
    lp, best, cal, theta, notes, sources
        The LogPosterior, ga_best.json, the resolved settings, the optimum, notes for the log and the
        noise scales' sources.
    """
    data, best, cal, theta, notes, sources = _read(modal_csv, scatter_csv, ga_best_json, assembly, cal, ps,
                                                   backbone_csv)
    noise_max = (ps.noise_max["frequency"], ps.noise_max["damping"])
    problems = data_problem(data, noise_max=noise_max, where=str(modal_csv))
    stop = [text for kind, text in problems if kind in ("two_modes", "noise")]
    if stop:  # the sentence names the cause in the data and the fix
        raise CalibrationInputError(stop[0])
    lp = LogPosterior(data, cal.space, cal.m, cal.model, cal.viscous, noise_max)
    return lp, best, cal, theta, notes + [text for _, text in problems], sources


def _fingerprint(data: ModalData, theta: np.ndarray, cal: CalibrateSettings, ps: PosteriorSettings) -> str:
    """What shapes the chain: the data, the start, the sampler's and the calibration's settings."""
    shape = dict(theta=theta.tolist(), seed=ps.seed, walkers=ps.n_walkers, ball=ps.ball, floors=dict(ps.rel_std_floor),
                 noise_max=(ps.noise_max["frequency"], ps.noise_max["damping"]),
                 cal=[cal.model, cal.viscous, cal.damping, cal.m, cal.full_bounds])
    fp = hashlib.sha256(json.dumps(shape, sort_keys=True).encode())
    for a in (data.q, data.f, data.zeta) + (() if data.weight is None else (data.w,)):
        fp.update(a.tobytes())
    return fp.hexdigest()


def _resume(ckpt: Path | None, fingerprint: str, notes: list[str]) -> dict | None:
    """Step 2, decide where to start: the checkpoint's chain when it was made from the same inputs."""
    if ckpt is None or not ckpt.is_file():
        return None
    try:
        with np.load(ckpt) as z:
            saved = {k: z[k] for k in z.files}
    except Exception as exc:  # a damaged checkpoint only costs the time to recompute
        notes.append(f"{ckpt}: unreadable checkpoint ({type(exc).__name__}); starting afresh")
        return None
    if str(saved.get("fingerprint")) != fingerprint:
        notes.append(f"{ckpt}: checkpoint made with other data or settings; starting afresh")
        return None
    notes.append(f"{ckpt}: resuming the chain after {len(saved['chain'])} steps")
    return dict(chain=saved["chain"], log_prob=saved["log_prob"], tau_history=list(saved["tau_history"]),
                accepted=saved["accepted"], random_state=random_state_tuple(saved))


def _arrays(lp: LogPosterior, fingerprint: str, chain, log_prob, random_state, tau_history, accepted) -> dict:
    """The chain's arrays as chain.npz and the checkpoint store them."""
    return dict(chain=chain, log_prob=log_prob, tau_history=np.asarray(tau_history), accepted=accepted,
                names=np.array(lp.names), q_ref=lp.q_ref, fingerprint=np.array(fingerprint),
                **random_state_arrays(random_state))


def _sample(lp: LogPosterior, theta: np.ndarray, ps: PosteriorSettings, fingerprint: str, resume: dict | None,
            ckpt: Path | None, progress: Callable[[str], None] | None) -> ChainResult:
    """Step 3: emcee from a ball around the optimum (or the checkpoint), saved and reported after every chunk."""
    def save(state: dict) -> None:
        if ckpt is not None:
            write_bytes_atomic(_npz(_arrays(lp, fingerprint, **state)), ckpt)
        if progress is not None:
            n, *tau = state["tau_history"][-1]
            tmax = float(np.max(tau))
            progress(f"posterior step {int(n)}/{ps.max_steps}: largest autocorrelation time {tmax:.0f} steps, "
                     f"chain {n / tmax:.1f} tau (stops at {ps.tau_factor:g} tau)"
                     + (f"; checkpoint {ckpt}" if ckpt is not None else ""))

    return run_chain(lp, start_ball(lp, theta, ps), seed=ps.seed, max_steps=ps.max_steps, chunk=ps.chunk,
                     tau_factor=ps.tau_factor, tau_rtol=ps.tau_rtol, stop_projected=ps.stop_projected,
                     min_chunks=ps.min_chunks, observe=lambda c: lp.space.columns(lp.to_x(c), OBSERVED),
                     resume=resume, on_chunk=None if ckpt is None and progress is None else save)


def _chain_sentence(res: ChainResult, ps: PosteriorSettings, burn: int) -> str:
    """One sentence on the chain: walkers, steps in units of tau, whether (and why not) it converged."""
    tmax = float(np.max(res.tau))
    rule = f"{ps.tau_factor:g}-tau rule"
    if res.converged:
        status = f"converged by the {rule}"
    elif res.stop_reason == "projected":
        status = (f"NOT converged: stopped early, {ps.tau_factor:g} tau would need about {res.projected_steps:.0f} "
                  f"steps (extrapolated from the running tau) > {ps.stop_projected:g} x max_steps {ps.max_steps}"
                  if np.isfinite(res.projected_steps) else
                  f"NOT converged: stopped early, the chain length in units of tau stopped growing (the walkers "
                  f"do not mix), so {ps.tau_factor:g} tau is out of reach of max_steps {ps.max_steps}")
        status += "; treat the intervals as provisional"
    else:
        status = f"NOT converged: stopped at max_steps {ps.max_steps}; treat the intervals as provisional"
    return (f"emcee: {ps.n_walkers} walkers, {res.steps} steps = {res.steps / tmax:.1f} x the largest "
            f"autocorrelation time ({tmax:.0f} steps); {status}; burn-in {burn} steps; mean acceptance "
            f"{np.mean(res.acceptance):.2f}.")


def run_posterior(modal_csv: str | os.PathLike[str], scatter_csv: str | os.PathLike[str],
                  ga_best_json: str | os.PathLike[str], assembly: str, out_dir: str | os.PathLike[str],
                  cal: CalibrateSettings, ps: PosteriorSettings, *,
                  checkpoint: str | os.PathLike[str] | None = None,
                  progress: Callable[[str], None] | None = None,
                  backbone_csv: str | os.PathLike[str] | None = None) -> tuple[ChainResult, list[str]]:
    """Sample one assembly's posterior and write the stage's outputs: read, decide where to start, sample, write.

    Parameters
    ----------
    modal_csv, scatter_csv : path-like
        The modal stage's tables.
    ga_best_json : path-like
        The calibration stage's ``ga_best.json`` for this assembly (the start).
    assembly : str
    out_dir : path-like
        Folder for `OUTPUTS` (created).
    cal, ps : CalibrateSettings, PosteriorSettings
    checkpoint : path-like, optional
        ``.npz`` checkpoint: resumed from when it matches, rewritten after every chunk.
    progress : callable, optional
        Receives one line (steps so far, largest running autocorrelation time, chain
        length in units of it) after every chunk, for the stage's log.
    backbone_csv : path-like, optional
        The unit's ``backbone.csv``, as the calibration read it (`jointcal.calibrate.read_modal`).

    Returns
    -------
    result : ChainResult
    notes : list of str
        Lines for the log (floors used, resume, convergence).
    """
    lp, best, cal, theta, notes, sources = posterior_of(modal_csv, scatter_csv, ga_best_json, assembly, cal, ps,
                                                        backbone_csv)
    data = lp.data
    fingerprint = _fingerprint(data, theta, cal, ps)
    ckpt = None if checkpoint is None else Path(checkpoint)
    res = _sample(lp, theta, ps, fingerprint, _resume(ckpt, fingerprint, notes), ckpt, progress)
    head, fit_line = _write(Path(out_dir), lp, res, theta, best, cal, ps, fingerprint, sources)
    notes += [head, fit_line,
              f"noise floors (relative): frequency {data.rel_noise[0]:.3g}, damping {data.rel_noise[1]:.3g}"]
    return res, notes


def _write(out: Path, lp: LogPosterior, res: ChainResult, theta: np.ndarray, best: dict, cal: CalibrateSettings,
           ps: PosteriorSettings, fingerprint: str, sources: tuple[str, str] = ("repeats", "repeats")
           ) -> tuple[str, str]:
    """Step 4, write: summary.csv, chain.npz (with the draws and their modes), constraints.txt, predictive.csv."""
    space, data = lp.space, lp.data
    chain_x = lp.to_x(res.chain)
    burn = burn_in(res.tau, res.steps, ps.burn_tau)
    summary = summarize(chain_x, lp.lower, lp.upper, burn=burn, ratio=ps.constrained_ratio, space=space)
    kept = chain_x[burn:].reshape(-1, lp.ndim)
    labels = mode_labels(kept, seed=ps.seed)  # in x: log10 of the scale parameters
    modes = find_modes(lp.physical(kept), lp.sample_names, labels=labels)
    # draws spread over steps and walkers alike (an even stride through the flattened chain can alias with the
    # number of walkers and keep only a few of them)
    pick = np.sort(np.random.default_rng(ps.seed).choice(len(kept), min(ps.predictive_draws, len(kept)),
                                                         replace=False))
    samples = lp.physical(kept[pick])
    q = np.geomspace(data.q.min() / cal.curve_widen, data.q.max() * cal.curve_widen, cal.curve_points)
    band = predictive_band(space.joint(samples), q, m=cal.m, model=cal.model, viscous=cal.viscous)
    head = _chain_sentence(res, ps, burn)
    fit_ratio, fit_line = goodness_of_fit(lp, theta, sources=sources)
    text = (head + "\n" + fit_line + "\n" + modes_text(modes, space.names, converged=res.converged) + "\n"
            + constraints_text(summary, chain_x, burn=burn, q_max=float(data.q.max()), ratio=ps.constrained_ratio,
                               space=space))
    if cal.model_kind == "modal":  # what the numbers mean: per unit modal mass, the rig's mode for a voltage
        text = text.rstrip("\n") + "\n" + model_words(best) + "\n"
    write_csv_atomic(summary, out / "summary.csv")
    final = _arrays(lp, fingerprint, res.chain, res.log_prob, res.random_state, res.tau_history,
                    res.acceptance * res.steps)
    final.update(samples=samples, sample_names=np.array(lp.sample_names), burn=burn, converged=res.converged,
                 stop_reason=np.array(res.stop_reason), projected_steps=res.projected_steps,
                 sample_mode=labels[pick], fit_ratio=np.asarray(fit_ratio), noise_source=np.array(sources),
                 **fit_test(lp, theta))
    write_bytes_atomic(_npz(final), out / "chain.npz")
    out.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(text.encode(), out / "constraints.txt")
    write_csv_atomic(band, out / "predictive.csv")
    return head, fit_line
