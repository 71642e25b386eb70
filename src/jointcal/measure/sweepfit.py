"""Resonance and damping of a swept run from its whole transient, at the amplitude it reached.

A lab's FRF (`jointcal.measure.frf`) assumes each line is a steady state. A chirp faster than a
lightly damped nonlinear mode can follow breaks that: the amplitude never builds, the
response rings on after the drive has moved away, and a softening joint's peak is read
at amplitudes it never had. Here the run is instead fitted, sample by sample, with one
mode whose natural frequency and damping depend on its amplitude, driven by the
measured reference:

    x_a'' + (1 - phi) D(q) x_a' + (Omega(q)^2 + i phi D(q) Omega(q)) x_a = A(w) r_a(t),    q = |x_a|,

with x_a, r_a the analytic signals of the displacement and the reference, D = 2 zeta
Omega shared between a viscous part and a hysteretic part phi (a joint's friction: its
loss per cycle does not grow with frequency; phi matters where the data lie off Omega,
e.g. a force-driven rig's response peaks at the shaker-loaded resonance), and A(w) the
modal constant at the drive frequency w: 1/m for a force at the driving point (real, no
slope; a phase only where a response channel lags the force and the phase earns its place), complex and linear in w for an amplifier voltage, A = A_0 + A_1 (w / W_0 - 1)
(the shaker's electrical phase and the residual modes).

Written in a frame rotating at the fixed frequency W_0 (the start value), x_a = Z e^{i W_0 t},
r_a = R e^{i W_0 t}, this is exactly

    Z'' + (2 i W_0 + c) Z' + (Omega^2 - W_0^2 + i (c W_0 + phi D Omega)) Z = A_0 R - i A_1 R' / W_0,   c = (1 - phi) D,

(w r_a becomes W_0 R - i R' in the frame, so the slope needs no estimate of the drive
frequency). Z and R are the measured signals demodulated at W_0 and low-passed at
`cutoff` W_0: the mode's resonant passage, its forced response within that band and its
free ring-down after the drive has left (or stopped) all stay in the band, while the
drive far from the mode (a chirp from almost 0 Hz), other modes and harmonics are
filtered out of the data and the model alike. A fixed frame makes the low-pass the same
for the ring-down and the forced response: a frame that follows the drive would filter
the ring-down out of the data once the drive has moved on, but not out of the model.
The equation is integrated by RK4 at a few steps per cycle (the negative-frequency root
-(Omega + W_0) bounds the step), and its acceleration Z'' + 2 i W_0 Z' - W_0^2 Z is compared
with the measured one, sample by sample, over the passage through resonance and the
ring-down (`window`). For a linear mode this is the exact response at any sweep rate; for
an amplitude-dependent one it is the first-harmonic (averaged) response, the same
approximation as the harmonic-balance truth.

ln Omega^2(q) and ln D(q) are a cubic and a quadratic in L = ln(q / q_ref) around the
largest amplitude the run reached, q_ref (a power law, as a joint's microslip softening and
loss, eq. 3.5, has in its first term, is a straight line in L; D stays positive), held
constant outside the amplitudes the fitted window holds. The frequency's curvature (the
Table 3.2 joint's softening steepens toward macroslip) is kept only where the Bayesian
information criterion of the misfit asks for it (a curvature fitted to noise bends the
backbone's ends: +0.14% at q_in on a jointed beam at eta 500); the damping's carries a
ridge (`curv`). The fit
(`scipy.optimize.least_squares`: the modal constant, the shape coefficients, Omega and D at
q_ref, phi in [0, 1], and residual terms (B_0 + B_1 (w / W_0 - 1) + B_2 (w / W_0 - 1)^2) r_a for
the other modes' mass or stiffness lines; its Jacobian by the RK4 step's forward
sensitivities, `jointcal.measure._rotating_sensitivity`, exact for the discrete model)
returns Omega and zeta = D / (2 Omega) at the largest amplitude the fitted response
reached, `q_in`: the equivalent-linear resonance and damping at the amplitude the
structure reached, and the backbone below it.

Bad samples (NaN or inf) in either channel are left out: the response's frames within a
filter length of them leave the misfit, and the drive's demodulated envelope is bridged
across them as the swept sine it is (a quadratic phase and a log-linear magnitude fitted on
both sides).

A fast chirp's integration starts from rest at the record's start (the sweep's start). A record
that begins with the mode already moving (cut from a longer run, or the drive on before the
recording) contradicts that: where the fit from rest misses the response there by more than
`quiet` of its peak, the run is fitted again from a low-pass reach into the record, from a start
state fitted with the mode, and that fit is kept where the information criterion asks for it.

A force at the driving point fixes A's phase at 0, and with it the phase at resonance (-90 deg), which
pins the frequency. A response channel that lags the force channel (a delay tau: filters, conditioners)
turns the measured response by -w tau, -W_0 tau across the narrow passage (its change over the passage,
tau (w - W_0), is under a degree for the jointed beam's 14 deg at the mode). A real A cannot follow that: on
the jointed beam (tau 4e-4 s, 14 deg at 98.5 Hz) the fit took the hysteretic share phi to 1, the damping 45%
high and |A| 33% above 1/m (misfit 0.051, under `modal.sweep_misfit`: read silently). So with a fixed phase
the fit is also run with A's quadrature part free (one parameter, `_sweep_problem.PHASE`), and that fit is
kept where it earns its place as the residual terms must (`_sweep_problem.earns`: the information criterion
and the misfit's sum of squares cut by `earn`) and is a lag, as a delay's is (`_lags`; a lead is a neighbouring
mode's line or the model's own misfit, left as before): on that run the damping 0.0121 (harmonic balance 0.0120),
|A| 385.1 (1/m 386.1), A's phase -13.8 deg (-W_0 tau -14.2), misfit 0.006. A's phase is then the channels',
not the force's: `jointcal.validate.drive.drive_gain` drives the model with |A| alone (the sign of A's
real part kept).

An amplifier voltage drives the mode through the shaker's coil, whose corner R / L can sit near the
mode (0.74 of it on the Ministack rig): its back-EMF damping then falls across the resonance, which
A(w)'s slope only approximates. With `coil` the run is refitted with the coil as it is built
(`jointcal.measure._coil`: the coil current a third state, its corner w_e and back-EMF gain g;
`jointcal.measure._coil_fit`): the two fitted (`coil='fit'`, kept where the information criterion
asks for them), or a campaign's held (`jointcal.measure.campaign.assembly_coil`: fitted on its
slowest sweeps, where one fast chirp barely identifies them); f_hz and zeta are then the coupled pole's.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ._coil import coil_pole
from ._coil_fit import refit_with_coil
from ._rotating import baseband, demodulate, head_end, passage
from ._sweep_problem import PHASE, Problem, earned_terms, earns, fit_from_starts

__all__ = ["SweepFit", "baseband", "fit_swept_mode", "WINDOW"]

WINDOW = 0.15  # the fitted stretch: where the response's envelope exceeds this fraction of its peak


@dataclass(frozen=True)
class SweepFit:
    """A swept run's amplitude-dependent single-mode fit.

    f_hz, zeta : natural frequency Omega / 2 pi (Hz) and damping ratio at q_in.
    q_in : the largest displacement amplitude the fitted response reached (in): the
        amplitude f_hz and zeta belong to.
    q_low_in : the smallest amplitude the fitted window holds (in); the backbone
        (`backbone`) is fitted over [q_low_in, q_in].
    residual : relative RMS misfit of the response's acceleration envelope over the window.
    coef : (Omega_ref^2 (rad^2/s^2), D_ref (1/s), a1, a2, b1, b2, phi, q_ref (in), L_lo, L_hi, a3):
        Omega^2 = Omega_ref^2 exp(a1 L + a2 L^2 + a3 L^3), D = 2 zeta Omega = D_ref exp(b1 L + b2 L^2),
        L = ln(q / q_ref) held within [L_lo, L_hi]; phi the hysteretic share of D (0 viscous,
        1 hysteretic).
    modal_constant : complex A_0 at W_0 ((in/s^2) per reference unit: 1/m in 1/(lbf s^2/in)
        for a force at the driving point).
    modal_slope : complex A_1 (same unit): A(w) = A_0 + A_1 (w / W_0 - 1).
    w0 : the frame's frequency W_0, rad/s.
    fraction_bad : share of the fitted window left out for bad samples.
    ringing_end : the record ended with the response still over `window` of its peak: the free decay
        that fixes the damping is cut.
    start_fitted : the record began with the mode already moving (the fit from rest missed the
        response at the record's start by more than `quiet` of its peak), and the fit kept is the one
        from a fitted state a low-pass reach in.
    coil : (w_e, g) or None
        A voltage drive's coil in the fit: its corner R / L (rad/s) and back-EMF gain (1/s^2); f_hz, zeta
        and `backbone` are then the pole of the mode with its coil, coef the mode's own.
    """

    f_hz: float
    zeta: float
    q_in: float
    q_low_in: float
    residual: float
    coef: tuple
    modal_constant: complex = complex("nan")
    modal_slope: complex = 0j
    w0: float = float("nan")
    fraction_bad: float = 0.0
    ringing_end: bool = False
    start_fitted: bool = False
    coil: tuple | None = None

    def coil_text(self) -> str:
        """The coil's constants in words (empty without a coil)."""
        return "" if self.coil is None else f"coil w_e {self.coil[0]:.6g} rad/s, g {self.coil[1]:.6g} 1/s^2"

    def backbone(self, q: NDArray) -> tuple[NDArray, NDArray]:
        """Natural frequency (Hz) and damping ratio at amplitudes q (in) (fitted over [q_low_in, q_in])."""
        w2r, dr, a1, a2, b1, b2, _, qr, l_lo, l_hi, a3 = self.coef
        L = np.clip(np.log(np.asarray(q, float) / qr), l_lo, l_hi)
        om = np.sqrt(w2r * np.exp(a1 * L + a2 * L**2 + a3 * L**3))
        if self.coil is not None:  # the pole of the mode with its coil
            return coil_pole(om**2, dr * np.exp(b1 * L + b2 * L**2), *self.coil)
        return om / (2 * np.pi), dr * np.exp(b1 * L + b2 * L**2) / (2 * om)  # at w = Omega


def _lags(sol, free: NDArray) -> bool:
    """Whether a fit with A's quadrature part free (`_sweep_problem.PHASE`) puts the response behind the force: A's
    phase at the mode below 0. A channel's delay only lags (-W_0 tau, tau > 0); a lead is not a delay (on the jointed
    beam with a neighbouring mode above, the fit took a lead of 1.1-1.6 deg growing with the level and |A| 3-5% above
    1/m: the neighbour's line, which the force held real leaves to the discrepancy stage's library)."""
    p = np.zeros(max(int(np.max(free)) + 1, PHASE + 1))
    p[free] = sol.x
    return bool(np.angle(p[6] + 1j * p[PHASE]) < 0.0)


def fit_swept_mode(ref: NDArray, resp_g: NDArray, fs: float, f0: float, zeta0: float, *,
                   modal_phase: float | None = None, window: float = WINDOW, cutoff: float = 0.45,
                   steps_per_cycle: float = 6.0, quiet: float = 0.02, ridge: float = 0.01,
                   curv: float = 0.3, residual_ridge: float = 0.3,
                   frequency_curvature: str = "bic", earn: float = 1.5,
                   jacobian: Literal["sensitivity", "2-point"] = "sensitivity",
                   coil: Literal["fit"] | tuple[float, float] | None = None) -> SweepFit:
    """Fit one amplitude-dependent mode to a swept run (see the module docstring).

    Parameters
    ----------
    ref : ndarray, shape (n,)
        Reference channel (force, lbf; amplifier voltage, V; any unit: A absorbs it); NaN or
        inf samples are bridged.
    resp_g : ndarray, shape (n,)
        Response acceleration at the driving point (or any point of a single mode), g; NaN
        or inf samples are left out of the misfit.
    fs : float
        Sample rate, Hz.
    f0, zeta0 : float
        Start values: the resonance (Hz) and damping ratio (e.g. from the FRF read-out). f0
        is also the frame's frequency W_0 / 2 pi.
    modal_phase : float, optional
        The modal constant's phase where physics fixes it (rad): 0 for a force on the
        structure (A = 1/m, no frequency dependence), no slope; the response channel's lag behind the
        reference (a channel delay) is fitted as a further phase of A only where it earns its place
        (module notes). None (an amplifier voltage): A complex and sloped in w.
    window : float
        Samples of the contiguous stretch around the response's peak whose envelope
        exceeds this fraction of the peak are fitted (the passage through resonance and
        the ring-down); default `WINDOW`.
    cutoff : float
        Low-pass of the demodulated signals, as a fraction of f0: other modes must lie
        further than this from f0 (0.45: beyond 0.55 f0 and 1.45 f0; a mode within is
        not separated from this one).
    steps_per_cycle : float
        RK4 steps per period at f0, about (the rotating frame's fast root -(Omega + W_0)
        bounds it: 6 keeps |lambda| h near 2.1, under RK4's 2.8).
    quiet : float
        The integration starts at the last sample before the window where the envelope is
        under this fraction of its peak, from the forced state there.
    ridge : float
        Weight of a ridge penalty on the nuisance terms (the modal constant's slope over its
        value, the residual terms over the peak): a value of 1 costs as much as a relative
        misfit of `ridge` on every sample.
    frequency_curvature : {'bic', 'always', 'never'}
        Whether ln Omega^2 takes its quadratic and cubic terms in L: where the Bayesian information
        criterion of the misfit asks for them (default), always or never.
    earn : float
        The residual terms are kept only where they pass the Bayesian information criterion and cut
        the misfit's sum of squares by this factor.
    jacobian : {'sensitivity', '2-point'}
        The least-squares Jacobian: the RK4 step's forward sensitivities, exact for the discrete model
        (`jointcal.measure._rotating_sensitivity`; one integration with its derivatives per Jacobian), or
        scipy's forward differences (one integration per free parameter; the earlier scheme, kept to
        compare with).
    coil : 'fit', (w_e, g) or None
        A voltage drive's coil (module docstring): fitted, held at its corner w_e (rad/s) and back-EMF
        gain g (1/s^2), or left out (default: A(w)'s slope stands for it).
    residual_ridge : float
        The residual terms' share of that penalty (0.3: other modes' lines must be free enough to
        follow a second mode's stiffness line over the band, whose curvature biased the resonance
        by +0.05-0.1% on a jointed beam at eta 500 with only the constant and slope terms).
    curv : float
        The same penalty, times curv, on the curvature of ln D in L over the window
        (b2 L_lo^2): the damping is a power law in q unless the data ask for more (measured
        on a jointed beam at eta 500 with 2% noise: the damping at the window's ends off by
        5-11% without it, within 2% with 0.3). The frequency's curvature, which the phase
        pins, is free.

    Returns
    -------
    SweepFit

    Raises
    ------
    ValueError
        When the record holds no drive or no response, or too few good samples; for an unknown `jacobian`.
    """
    if jacobian not in ("sensitivity", "2-point"):
        raise ValueError(f"jacobian must be 'sensitivity' or '2-point', not {jacobian!r}.")
    sig = demodulate(ref, resp_g, fs, f0, zeta0, cutoff, steps_per_cycle)

    def fit(free_start):
        prob = Problem.build(passage(sig, window, quiet, steps_per_cycle, free_start), f0, zeta0, window, modal_phase,
                             ridge, curv, residual_ridge, jacobian)
        free = prob.free_all[~np.isin(prob.free_all, (3, 15))]  # ln Omega^2 linear in L first; its curvature if asked
        best = fit_from_starts(prob, free, f0, zeta0)
        if prob.fixed:  # the channels' phase at the mode, where it earns its place (module notes)
            lagged = np.union1d(free, [PHASE])
            trial = fit_from_starts(prob, lagged, f0, zeta0)
            if earns(prob, trial, best, 1, earn):
                out = earned_terms(prob, trial, lagged, frequency_curvature, earn)
                if _lags(*out):  # judged with the residual terms it keeps (they can turn a small lag into a lead)
                    return (prob, *out)
        return (prob, *earned_terms(prob, best, free, frequency_curvature, earn))

    if coil is not None and not (coil == "fit" or len(coil) == 2 and coil[0] > 0 and coil[1] >= 0):
        raise ValueError(f"coil must be 'fit', (w_e > 0, g >= 0) or None, not {coil!r}.")
    chosen = rest = fit(False)
    if _starts_moving(*rest, quiet):
        moving = fit(True)  # the record began with the mode already moving: its start state fitted
        n_eff = moving[0].n_res / 2
        ratio = (rest[0].relative(rest[1]) / moving[0].relative(moving[1])) ** 2  # the misfits' sums of squares
        chosen = moving if n_eff * np.log(ratio) > 4 * np.log(n_eff) else rest
    return _result(*(chosen if coil is None else refit_with_coil(*chosen, coil)))


def _starts_moving(prob: Problem, best, free: NDArray, quiet: float) -> bool:
    """Whether the fit from rest at the record's start misses the response there, within a low-pass
    reach, by more than `quiet` of its peak: the record began with the mode already moving."""
    ps = prob.ps
    if ps.i_start != 0 or ps.free_start or ps.sig.reach == 0:
        return False
    head = slice(ps.sig.first, head_end(ps.sig) + 1)
    _, acc = prob.response(best.x, free)
    gap = np.abs(acc[head] - ps.sig.Acc[head])[ps.sig.ok[head]]
    return bool(gap.size and gap.max() > quiet * prob.peak)


def _result(prob: Problem, best, free: NDArray) -> SweepFit:
    """The fit's resonance and damping at the largest amplitude its response reached, and its backbone."""
    mode, _ = prob.params(best.x, free)
    Z, _ = prob.response(best.x, free)
    coil = None if prob.coil is None else (float(mode[12]), float(mode[13]))
    # over the whole window: a bad stretch at the peak leaves the misfit, not the amplitude reached
    win = prob.ps.inside
    q_top = float(np.abs(Z[win]).max())
    coef = (*(float(v) for v in mode[:6]), float(mode[8]), prob.q_ref, prob.l_lo, prob.l_hi, float(mode[11]))
    fit = SweepFit(f_hz=np.nan, zeta=np.nan, q_in=q_top, q_low_in=float(np.abs(Z[win]).min()),
                   residual=prob.relative(best), coef=coef, modal_constant=complex(mode[6], mode[7]),
                   modal_slope=complex(mode[9], mode[10]), w0=prob.ps.sig.W0, fraction_bad=prob.ps.fraction_bad,
                   ringing_end=prob.ps.ringing_end, start_fitted=prob.ps.free_start, coil=coil)
    f, z = fit.backbone(q_top)
    return SweepFit(**{**fit.__dict__, "f_hz": float(f), "zeta": float(z)})
