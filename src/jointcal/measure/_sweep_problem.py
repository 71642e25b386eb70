"""The least-squares problem of the swept-mode fit, its start values and the terms the data must ask for.

Private: `jointcal.measure.sweepfit.fit_swept_mode` builds a `Problem` of one passage,
fits it from `fit_from_starts`' start values and keeps the optional terms `earned_terms`
accepts.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ._coil import N_COIL_DIRECTIONS, coil_mode_sensitivity
from ._rotating import Passage, rotating_mode
from ._rotating_sensitivity import N_DIRECTIONS, rotating_mode_sensitivity
from ._sweep_starts import starts as _starts

__all__ = ["PHASE", "Problem", "fit_from_starts", "earned_terms", "earns"]


PHASE = 7  # with a fixed phase (a force): p[7], A's part in quadrature with the fixed phase (A = a_abs (p[6] + i p[7])
# e^{i phase}): 0, or fitted where the channels' phase earns its place (`sweepfit.fit_swept_mode`)
NP = 24  # parameters: the mode's 18, its start state's 4 where the record begins in motion, a coil's 2
X_SCALE = np.array([1e-3, 0.1, 0.01, 0.01, 0.2, 0.2, 0.1, 0.1, 0.2, 0.5, 0.5, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01,
                    0.05, 0.05, 0.05, 0.05, 0.05, 0.01])
COIL_RANGE = (0.05, 2.0)  # the coil's corner w_e / W0 fitted within (RK4's step bounds |w_e + i W0| h)
LOWER, UPPER = np.full(NP, -np.inf), np.full(NP, np.inf)
LOWER[8], UPPER[8] = 0.0, 1.0  # phi, the hysteretic share of the damping


@dataclass(frozen=True)
class Problem:
    """The least-squares problem of one passage: 22 scaled parameters (those in a `free` set fitted)
    map to the mode (`params`), whose response is compared with the measured one (`misfit`).

    p[0], p[1]: ln(Omega_ref / W0) and ln(D_ref / (2 zeta0 W0)); p[2:4], p[15]: ln Omega^2's linear,
    quadratic and cubic terms in L; p[4:6]: ln D's; p[6:8]: the modal constant over `a_abs`; p[8]: phi;
    p[9:11]: the modal constant's slope; p[11:15], p[16:18]: the residual terms over `b_abs`;
    p[18:22] (a passage with `free_start`): the start state's correction, Z over q_ref and Z' over
    q_ref W0, real and imaginary parts; p[22], p[23] (a voltage drive's coil, `jointcal.measure._coil`):
    w_e = coil[0] exp(p[22]) and g = coil[1] + W0^2 p[23], held (`coil` alone) or fitted (`coil_free`).
    """

    ps: Passage
    zeta0: float
    peak: float
    q_ref: float
    l_lo: float
    l_hi: float
    a_abs: float
    b_abs: float
    fixed: bool
    rot: complex
    free_all: NDArray
    weight: float
    ridge_terms: tuple[float, float]  # (residual_ridge, curv)
    residual_basis: NDArray
    norm: float
    n_res: int
    jacobian: str = "sensitivity"
    coil: tuple[float, float] | None = None  # (w_e rad/s, g 1/s^2): held, or the start where coil_free
    coil_free: bool = False
    memo: dict = field(default_factory=dict, init=False, compare=False, repr=False)  # the last Jacobian

    @classmethod
    def build(cls, ps: Passage, f0: float, zeta0: float, window: float, modal_phase: float | None, ridge: float,
              curv: float, residual_ridge: float, jacobian: str = "sensitivity") -> Problem:
        if not zeta0 > 0:
            raise ValueError("the swept-mode fit needs a drive, a response and start values f0 > 0, zeta0 > 0.")
        sig, sel = ps.sig, ps.sel
        peak = float(np.abs(sig.Acc)[sel].max())
        r_abs = float(np.abs(sig.R[sel]).max())
        if not r_abs > 0:
            raise ValueError("the drive channel holds no signal near the mode.")
        fixed = modal_phase is not None  # a force at the driving point: A = |A| e^{i phase}, no slope; real residuals
        W0 = sig.W0
        return cls(ps=ps, zeta0=zeta0, peak=peak, q_ref=peak / W0**2, l_lo=float(np.log(0.5 * window)),
                   l_hi=float(np.log(1.5)), a_abs=2 * zeta0 * peak / r_abs,  # |A| of a steady resonance:
                   b_abs=peak / r_abs, fixed=fixed,                          # |Acc| = |A| |R| / (2 zeta)
                   rot=np.exp(1j * modal_phase) if fixed else 1.0,
                   free_all=np.array(([0, 1, 2, 3, 4, 5, 6, 8, 11, 13, 15, 16] if fixed else list(range(18)))
                                     + ([18, 19, 20, 21] if ps.free_start else [])),
                   weight=ridge * np.sqrt(sel.sum()), ridge_terms=(residual_ridge, curv),
                   # the residual terms' basis: (w / W0 - 1)^k R for k = 0, 1, 2 in the frame (w R -> W0 R - i R')
                   residual_basis=np.stack([sig.R, -1j * sig.Rd / W0, -sig.Rdd / W0**2], axis=1),
                   norm=float(np.linalg.norm(sig.Acc[sel] / peak)), n_res=2 * int(sel.sum()), jacobian=jacobian)

    def params(self, pf: NDArray, free: NDArray) -> tuple[NDArray, NDArray]:
        """The mode's coefficients (`jointcal.measure._rotating.rotating_mode`'s p) and the residual terms."""
        p = np.zeros(NP)
        p[free] = pf
        W0, a_abs, zeta0 = self.ps.sig.W0, self.a_abs, self.zeta0
        a = (p[6] + 1j * p[7]) * self.rot if self.fixed else p[6] + 1j * p[7]  # fixed: p[7] (`PHASE`) 0 unless
        # freed (a response channel that lags the force: A = |A| e^{-i W0 tau} at the mode)
        mode = np.array([W0**2 * np.exp(2 * p[0]), 2 * zeta0 * W0 * np.exp(p[1]), p[2], p[3], p[4], p[5],
                         a.real * a_abs, a.imag * a_abs, p[8], p[9] * a_abs, p[10] * a_abs, p[15]])
        if self.coil is not None:
            mode = np.append(mode, [self.coil[0] * np.exp(p[22]), self.coil[1] + W0**2 * p[23]])
        return mode, self.b_abs * np.array([complex(p[11], p[12]), complex(p[13], p[14]), complex(p[16], p[17])])

    def response(self, pf: NDArray, free: NDArray) -> tuple[NDArray, NDArray]:
        """The mode's displacement envelope Z (in) and acceleration envelope with the residual terms (in/s^2)."""
        mode, b = self.params(pf, free)
        s = self.ps.sig
        p = np.zeros(NP)
        p[free] = pf
        z0, y0 = self._start(p)
        if self.coil is None:
            Z, acc = rotating_mode(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, self.q_ref, self.l_lo, self.l_hi, z0, y0)
        else:
            none = np.empty(0, np.int64)
            Z, acc, _ = coil_mode_sensitivity(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, self.q_ref, self.l_lo,
                                              self.l_hi, z0, y0, self._nu(), none, np.zeros((0, 0)), none)
        return Z, acc + self.residual_basis @ b  # residual terms: the other modes' mass or stiffness lines

    def with_coil(self, coil: tuple[float, float], free: bool) -> Problem:
        """The same passage with a voltage drive's coil (w_e rad/s, g 1/s^2): held, or fitted from it."""
        extra = [22, 23] if free else []
        return replace(self, coil=(float(coil[0]), float(coil[1])), coil_free=free,
                       free_all=np.concatenate([self.free_all[self.free_all < 22], extra]).astype(int))

    def _nu(self) -> complex:
        """Z' / Z at the passage's start (1/s; 0 from rest): the coil's forced start."""
        ps = self.ps
        return complex(ps.y_start / ps.z_start) if ps.z_start != 0 else 0j

    def _start(self, p: NDArray) -> tuple[complex, complex]:
        """The integration's start state (Z in, Z' in/s): the passage's, corrected where it is fitted."""
        ps = self.ps
        if not ps.free_start:
            return ps.z_start, ps.y_start
        return (ps.z_start + self.q_ref * complex(p[18], p[19]),
                ps.y_start + self.q_ref * ps.sig.W0 * complex(p[20], p[21]))

    def misfit(self, pf: NDArray, free: NDArray) -> NDArray:
        """Relative residuals over the samples fitted, then the ridge penalties. With the sensitivity
        Jacobian, its Jacobian is computed in the same integration and kept for `jacobian_matrix`."""
        p = np.zeros(NP)
        p[free] = pf
        if self.jacobian == "sensitivity":
            res, jac = self._with_jacobian(pf, free, p)
            self.memo["at"] = (pf.copy(), free.copy(), jac)
        else:
            with np.errstate(all="ignore"):  # a trial step may diverge: a large misfit, not a warning
                res = (self.response(pf, free)[1] - self.ps.sig.Acc)[self.ps.sel] / self.peak
        res = np.where(np.isfinite(res) & (np.abs(res) < 1e3), res, 1e3)
        return np.concatenate([res.real, res.imag, self._penalties(p, free)[0]])

    def jacobian_matrix(self, pf: NDArray, free: NDArray) -> NDArray:
        """d `misfit` / d pf, exact for the discrete model: the RK4 step's forward sensitivities
        (`jointcal.measure._rotating_sensitivity`), shape (misfit size, free.size)."""
        at = self.memo.get("at")
        if at is not None and np.array_equal(at[0], pf) and np.array_equal(at[1], free):
            return at[2]  # least squares asks for the Jacobian where it has just evaluated the misfit
        p = np.zeros(NP)
        p[free] = pf
        return self._with_jacobian(pf, free, p)[1]

    def _with_jacobian(self, pf: NDArray, free: NDArray, p: NDArray) -> tuple[NDArray, NDArray]:
        """The relative residuals over the samples fitted (complex, unclamped) and the misfit's Jacobian."""
        mode, b = self.params(pf, free)
        s, sel = self.ps.sig, self.ps.sel
        chain = self._chain()[:, free]  # d (kernel direction) / d pf
        dirs = np.flatnonzero(np.any(chain != 0, axis=1))
        if "basis" not in self.memo:  # the residual terms' columns at the samples fitted: constant
            self.memo["basis"] = (self.residual_basis[sel], self._residual_columns(sel))
        basis, columns = self.memo["basis"]
        z0, y0 = self._start(p)
        with np.errstate(all="ignore"):  # a trial step may diverge: a large misfit, not a warning
            if self.coil is None:
                _, acc, dacc = rotating_mode_sensitivity(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, self.q_ref,
                                                         self.l_lo, self.l_hi, z0, y0, dirs, chain[dirs],
                                                         np.flatnonzero(sel))
            else:
                _, acc, dacc = coil_mode_sensitivity(s.R, s.Rd, s.Rm, s.Rdm, s.W0, s.h, mode, self.q_ref, self.l_lo,
                                                     self.l_hi, z0, y0, self._nu(), dirs, chain[dirs],
                                                     np.flatnonzero(sel))
            res = (acc[sel] + (basis[:, 0] * b[0] + basis[:, 1] * b[1] + basis[:, 2] * b[2]) - s.Acc[sel]) / self.peak
            jac = (dacc + columns[:, free]) / self.peak
        jac[~(np.isfinite(res) & (np.abs(res) < 1e3))] = 0.0  # a clamped residual does not move
        jac = np.where(np.isfinite(jac), jac, 0.0)
        return res, np.concatenate([jac.real, jac.imag, self._penalties(p, free)[1]])

    def _penalties(self, p: NDArray, free: NDArray) -> tuple[NDArray, NDArray]:
        """The ridge penalties and their derivatives in the free parameters, shape (k,) and (k, free.size)."""
        # a ridge on the nuisance terms (the modal constant's slope relative to it, the residual terms
        # relative to the peak): they stay small unless the data ask for them (an impulse-like chirp
        # cannot tell a feedthrough from the mode's response while the drive passes)
        residual_ridge, curv = self.ridge_terms
        a_norm = max(np.hypot(p[6], p[7]), 1e-12)
        nuisance = np.concatenate([p[9:11] / a_norm, residual_ridge * np.concatenate([p[11:15], [0.0], p[16:18]])])
        grad = np.zeros((9, NP))
        grad[np.arange(9), np.arange(9, 18)] = [1 / a_norm] * 2 + [residual_ridge] * 4 + [0.0] + [residual_ridge] * 2
        if np.hypot(p[6], p[7]) > 1e-12:
            grad[0:2, 6:8] = -np.outer(p[9:11], p[6:8]) / a_norm**3
        rows = free[(free >= 9) & (free < 18)] - 9
        curvature = curv * p[5] * self.l_lo**2  # the damping's quadratic term's change over the window
        d_curvature = np.zeros((1, NP))
        d_curvature[0, 5] = curv * self.l_lo**2
        values = np.concatenate([self.weight * nuisance[rows], [self.weight * curvature]])
        return values, self.weight * np.concatenate([grad[rows], d_curvature])[:, free]

    def _chain(self) -> NDArray:
        """d (kernel direction) / d p, shape (N_DIRECTIONS, NP): how the scaled parameters enter the kernel."""
        t = np.zeros((N_DIRECTIONS if self.coil is None else N_COIL_DIRECTIONS, NP))
        a_abs, qw = self.a_abs, self.q_ref * self.ps.sig.W0
        t[0, 0], t[1, 1] = 2.0, 1.0  # ln Omega_ref^2 = ln W0^2 + 2 p[0]; ln D_ref = const + p[1]
        t[2, 2], t[3, 3], t[4, 4], t[5, 5], t[8, 8], t[11, 15] = 1.0, 1.0, 1.0, 1.0, 1.0, 1.0
        t[6, 6], t[7, 6] = (a_abs * self.rot.real, a_abs * self.rot.imag) if self.fixed else (a_abs, 0.0)
        t[6, 7], t[7, 7] = (-a_abs * self.rot.imag, a_abs * self.rot.real) if self.fixed else (0.0, a_abs)
        t[9, 9], t[10, 10] = a_abs, a_abs
        if self.ps.free_start:
            t[12, 18], t[13, 19], t[14, 20], t[15, 21] = self.q_ref, self.q_ref, qw, qw
        if self.coil is not None:
            t[16, 22], t[17, 23] = 1.0, self.ps.sig.W0**2  # ln w_e = ln coil[0] + p[22]; g = coil[1] + W0^2 p[23]
        return t

    def _residual_columns(self, sel: NDArray) -> NDArray:
        """d (residual terms' acceleration) / d p at the steps sel, shape (sel.sum(), NP): linear in p[11:15],
        p[16:18]."""
        basis = self.residual_basis[sel]
        cols = np.zeros((basis.shape[0], NP), complex)
        for k, (i_re, i_im) in enumerate(((11, 12), (13, 14), (16, 17))):
            cols[:, i_re] = self.b_abs * basis[:, k]
            cols[:, i_im] = 1j * self.b_abs * basis[:, k]
        return cols

    def solve(self, p0: NDArray, free: NDArray, max_nfev: int):
        """`scipy.optimize.least_squares` of `misfit` over the free parameters from p0 (their values)."""
        jac = self.jacobian_matrix if self.jacobian == "sensitivity" else "2-point"
        lower, upper = LOWER.copy(), UPPER.copy()
        if self.coil is not None:
            W0 = self.ps.sig.W0
            lower[22], upper[22] = np.log(np.array(COIL_RANGE) * W0 / self.coil[0])
            lower[23] = -self.coil[1] / W0**2  # g >= 0
        return least_squares(self.misfit, p0, jac=jac, args=(free,), x_scale=X_SCALE[free],
                             bounds=(lower[free], upper[free]), max_nfev=max_nfev)

    def relative(self, sol) -> float:
        """Relative RMS misfit of a solution: `SweepFit.residual`."""
        return float(np.linalg.norm(sol.fun[:self.n_res]) / self.norm)


def fit_from_starts(prob: Problem, free: NDArray, f0: float, zeta0: float):
    """The best least-squares solution from `jointcal.measure._sweep_starts.starts`' start values (lazily: a good
    fit ends the scan). A fixed phase freed (`PHASE` in `free`): the starts' modal constants complex."""
    s = prob.ps.sig
    best, rel = None, np.inf
    real = prob.fixed and PHASE not in free
    for f_s, z_s, a_s, b0_s, b1_s, b2_s in _starts(s.R, s.Rd, s.Rm, s.Rdm, s.Rdd, s.Acc, prob.ps.sel, s.h, s.W0, f0,
                                                   zeta0, real, prob.rot):
        p0 = np.zeros(NP)
        p0[:2] = np.log(f_s / f0), np.log(z_s * f_s / (zeta0 * f0))
        a_s = a_s / prob.a_abs / prob.rot
        p0[6], p0[7], p0[8] = a_s.real, (0.0 if real else a_s.imag), 0.5
        b = prob.b_abs
        p0[11:15] = (b0_s.real / b, b0_s.imag / b, b1_s.real / b, b1_s.imag / b)
        p0[16:18] = (b2_s.real / b, b2_s.imag / b)
        sol = prob.solve(p0[free], free, 100)
        if best is None or sol.cost < best.cost:
            best, rel = sol, prob.relative(sol)
        if rel < 0.02:  # a good fit: no more starts
            break
    return best


def earns(prob: Problem, sol_more, sol_less, k: int, factor: float) -> bool:
    """Whether a solution with k more parameters earns them: the Bayesian information criterion of the misfit (half
    the samples counted: the low-passed envelopes are correlated over two) and its sum of squares cut by `factor`."""
    n_eff = prob.n_res / 2
    rss_more, rss_less = (float(np.sum(x.fun[:prob.n_res] ** 2)) for x in (sol_more, sol_less))
    return bool(rss_more > 0 and rss_less > factor * rss_more and n_eff * np.log(rss_less / rss_more) > k * np.log(n_eff))


def earned_terms(prob: Problem, best, free: NDArray, frequency_curvature: str, earn: float):
    """The solution and free set once the optional terms have earned their place, or not.

    First the frequency's curvature (a2, a3), by the Bayesian information criterion of the
    misfit (half the samples counted: the low-passed envelopes are correlated over two); then
    whether the residual terms (other modes' lines) are needed at all: they must also cut the
    misfit's sum of squares by the factor `earn`. The single-mode model's own approximation
    leaves a systematic misfit that any extra term trims a little, and residual terms kept for
    that bend the backbone (a driving-point force on the Table 3.2 joint at eta 20: they trimmed
    the misfit by a factor 1.13 and put q_in's frequency +0.21% off, +0.09% without; a second
    mode's line cuts it 3.6-90x).
    """
    def refit(sol, old, new):
        p_now = np.zeros(NP)
        p_now[old] = sol.x
        return prob.solve(p_now[new], new, 60)

    curved = np.union1d(free, prob.free_all[np.isin(prob.free_all, (3, 15))])
    trial = refit(best, free, curved)
    if frequency_curvature == "always" or frequency_curvature == "bic" and earns(prob, trial, best, 2, 1.0):
        best, free = trial, curved
    no_b = free[~np.isin(free, (11, 12, 13, 14, 16, 17))]
    trial = refit(best, free, no_b)
    if earns(prob, best, trial, free.size - no_b.size, earn):
        return best, free
    return trial, no_b
