"""The envelope a swept-sine test shows: the steady-state model carried through the sweep's transient.

A sweep is not a sequence of steady states. Near a resonance the response lags the drive,
its peak is lower and later, and it rings on after the drive has passed; the lightly damped
low levels of a joint show it most (eta = r / (f zeta)^2, r the sweep rate in Hz/s).

Slow flow. Write the joint DOF as z = Re(Z e^{i phi}) with phi' = omega the drive and
omega' = alpha = 2 pi r, and condense the linear structure around it into its effective
inertia mu(omega) and base-load factor gamma(omega) (`envelope._structure_terms`; a
rigid base: mu = m omega^2, gamma = 1). A linear operator with frequency response P(omega)
acting on a slowly varying Z(t) e^{i phi} gives e^{i phi} (P Z - i P' Z' - (i/2) alpha P'' Z)
to first order in the envelope's rates, so the describing-function balance of the joint
DOF becomes the first-order equation

    (i mu' + C) Z' = F A - i F' A' - (i/2) alpha F'' A - (K_z(|Z|, omega) - mu + (i/2) alpha mu'' + alpha C' / 2) Z,

F = -gamma m, A the base acceleration's amplitude (in/s^2), K_z the joint DOF's dynamic
stiffness (`_envelope_kernel._stiffness`), C = dIm K_z / domega its dashpots (C' = dC/domega,
the quadratic damper's); on a rigid base without them, 2 i omega m Z' = -m A -
(K_z - m omega^2 + i alpha m) Z. The measured channel is the slug's absolute acceleration,
R = -(joint force) / m (the slug's own equation of motion), joint force (K_z + alpha C' / 2) Z
+ C Z', and T = R / A. For a linear structure the
slow flow reproduces the exact first-order sweep correction of an FRF H(omega),
T = H - (i alpha / 2) H'' (the chirp's phase expanded to second order inside the
convolution integral), and it drops only Z'' (relative size zeta / 2).

The drive's complex envelope. The envelopes demodulate every channel with one sweep phase phi
(integrated from the reference's ridge, `jointcal.measure.envelopes`); a drive that is not held in
phase with it, an open-loop force that dips and turns at the resonance, has the complex envelope
A(t) = |A| e^{i psi(t)}, psi its phase relative to phi (`SweepDrive.phase_rad`). Then

    A' / A = dlog|A|/dt + i dpsi/dt,

which the slow flow above already carries through its A' terms (F A - i F' A'); a constant psi
turns Z and R with A and leaves T = R / A unchanged, so only its rate enters the ratio. The
measured T of a frame is <R> / <A> over the envelopes' Hann window, the reference taken at its
actual phase, and so is the model's (`swept_transmissibility`). The drive between frames is the
frames' |A| and psi interpolated linearly (the window-averaged envelope, not the fine one: below).
On the virtual open-loop force rig (`tests/models/test_swept_drive.py`, frames of `run_envelope`)
against the time simulation of the same model, E over 0.05 dB / 0.3 deg (eta = r / (f zeta)^2):
the drive's magnitude only, E 0.6 / 4.3-4.4 / 22-34 at eta 0.5 / 2 / 10; the complex drive,
0.01 / 0.07-0.09 / 4.6-6.6 (0.003 dB and 0.03 deg rms at eta 2). What is left at eta 10 is the
window: the frames are the Hann average of a force that rings within one window, and a fine
drive taken from the record itself (not available to the fits) brings it to about 2.

Two evaluations:

* `quasi_steady`: Z = Z_0 + Z_1 with Z_0 the steady state (`steady_state`) and Z_1 its
  first-order correction in alpha and A'/A, from the balance linearised about Z_0,
  L[v] = (K_z - mu) v + Z_0 (dK_z / dlog q) Re(conj(Z_0) v) / q^2:
  L[Z_1] = -(i mu' + C) Z_0' - (i/2) alpha mu'' Z_0 - alpha C' Z_0 / 2 - i F' A' - (i/2) alpha F'' A, with Z_0' from
  L[dZ_0/domega] = F' A - (dK_z/domega - mu') Z_0 and L[A dZ_0/dA] = F A, and for a complex drive
  (A real in the drive's own frame) Z_0' = alpha dZ_0/domega + (dlog|A|/dt) A dZ_0/dA + i (dpsi/dt) Z_0,
  -i F' A' = -i F' A dlog|A|/dt + F' A dpsi/dt. Closed form,
  batched over parameter sets; it fails where the steady-state curve is steep (a softening
  peak's bent flank, a fold: L is singular there), and |Z_1| is capped at `CAP` |Z_0|.
* `swept_transmissibility` (`jointcal.models.swept_integrated`): the slow flow integrated by RK4 (`_envelope_kernel.slow_flow`)
  through the resonance, from the quasi-steady state at x = -`SPAN` (x = (f / f_res - 1) /
  zeta, in sweep order) to x = max(`SPAN`, 1.2 eta) (the ringing has decayed by e^-7
  there), and averaged over each frame's Hann window as the envelopes are (T = <R> / <A>,
  `jointcal.measure.envelopes.envelopes`); other frames take `quasi_steady`.

Against the exact-Iwan time simulation measured by the same envelopes (virtual-lab runs,
12.8 kHz and 10 kHz, 400-1200 Hz/s): the steady state with the former first-order group-delay
lag missed by up to 0.8 dB and 4 deg at eta 0.15 (a validation-style E of 0.65, 1.7-2 on the
Table 3.2 joints); `quasi_steady` by 0.5 dB and 6 deg on the bent flank; the integrated
envelope by at most 0.07 dB and 0.5 deg up to eta 1.5, an E of 0.12-0.22, the first-harmonic
model's own quasi-static floor (0.15-0.2 at eta 0.01). The channel delay's shift of the
envelope in time (tau alpha, below 1% of a half-power width in the library's range) is
neglected, as is the can's own transient where the fixture's mode lies inside the sweep.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _envelope_kernel as _k
from ..units import G
from .envelope import (  # envelope's public batch API, under this module's short names
    GAUSS_NODES as _NODES, GAUSS_WEIGHTS as _WEIGHTS, batch_field as _field, batch_shape as _batch_shape,
    joint_terms as _joint_terms, sweep_amplitudes as _amplitudes,
)
from .structure import MinistackModel, Neighbour, can_spring

__all__ = ["SweepDrive", "quasi_steady", "quasi_steady_runs", "sweep_eta", "CAP"]

CAP = 0.3  # largest first-order correction |Z_1| / |Z_0| (a steep flank or fold breaks the expansion)


@dataclass(frozen=True)
class SweepDrive:
    """A run's drive as its envelopes measured it, in time order (arrays shape (n,)).

    t_s : frame centres, s; f_hz : drive frequency, Hz; base_g : base-acceleration amplitude,
    g (> 0); window_s : length of the envelopes' Hann window, s; phase_rad : the drive's phase
    psi relative to the sweep phase the envelopes demodulate with, rad, unwrapped (None: 0, the
    drive in phase with the sweep, as a controlled base acceleration is). The drive's complex
    envelope is A = base_g e^{i psi} (an open-loop force turns in phase at the resonance).
    """

    t_s: NDArray[np.float64]
    f_hz: NDArray[np.float64]
    base_g: NDArray[np.float64]
    window_s: float
    phase_rad: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        n = np.size(self.t_s)
        if not (np.size(self.f_hz) == n == np.size(self.base_g) and n >= 4):
            raise ValueError(f"SweepDrive: t_s, f_hz and base_g need one value per frame (>= 4), got "
                             f"{np.size(self.t_s)}, {np.size(self.f_hz)}, {np.size(self.base_g)}.")
        if not (np.all(np.diff(self.t_s) > 0) and np.all(np.asarray(self.base_g) > 0) and self.window_s > 0):
            raise ValueError("SweepDrive: t_s must increase, base_g be positive and window_s positive, got "
                             f"window_s {self.window_s!r}.")
        if self.phase_rad is not None and not (np.size(self.phase_rad) == n and np.all(np.isfinite(self.phase_rad))):
            raise ValueError(f"SweepDrive: phase_rad needs one finite value per frame ({n}), got "
                             f"{np.size(self.phase_rad)}.")

    @cached_property
    def rates(self) -> tuple[NDArray, NDArray]:
        """Drive-frequency rate df/dt (Hz/s) and the drive's log-rate d log A / dt (1/s) at the frames:
        dlog|A|/dt, real, without a phase; dlog|A|/dt + i dpsi/dt, complex, with one (A'/A)."""
        dlog = np.gradient(np.log(self.base_g), self.t_s)
        if self.phase_rad is not None:
            dlog = dlog + 1j * np.gradient(np.asarray(self.phase_rad, float), self.t_s)
        return np.gradient(self.f_hz, self.t_s), dlog

    def at(self, t: ArrayLike) -> tuple[NDArray, ...]:
        """f (Hz), base |A| (g), df/dt (Hz/s), d log A/dt (1/s; complex with a phase) interpolated at times t (s)."""
        r, dl = self.rates
        return tuple(np.interp(t, self.t_s, v) for v in (self.f_hz, self.base_g, r, dl))

    def phase_at(self, t: ArrayLike) -> NDArray[np.float64]:
        """The drive's phase psi (rad) interpolated at times t (s); 0 without a phase."""
        if self.phase_rad is None:
            return np.zeros(np.shape(t))
        return np.interp(t, self.t_s, self.phase_rad)


def sweep_eta(rate_hz_per_s: float, f_res_hz: float, zeta: float) -> float:
    """eta = |r| / (f_res zeta)^2: how far a sweep is from a sequence of steady states."""
    return abs(rate_hz_per_s) / (f_res_hz * zeta) ** 2


def _derivs(model: MinistackModel, w: NDArray, shape) -> tuple[NDArray, ...]:
    """mu, mu', mu'' and F = -gamma m, F', F'' at w (rad/s), each (P, N); derivatives in omega.

    Fixture (`envelope._structure_terms`): mu = m omega^2 + m^2 omega^4 / a11, gamma = kc / a11 with
    kc = k_can + i omega c_can and a11 = kc - omega^2 (m_can + m), differentiated in closed form.
    """
    m = _field(model.m, shape)[:, None]
    z = np.zeros((shape[0], w.size), complex)
    if _looped(model):
        return _loop_derivs(model, w, shape)
    if model.fixture is None:  # real values as complex arrays (P, N)
        out = [np.empty_like(z) for _ in range(4)]
        for o, v in zip(out, (m * w**2, 2 * m * w, 2 * m, -m)):
            o.real, o.imag = v, 0.0
        return (*out, z, z)
    fx = model.fixture
    mc = _field(fx.m_can, shape)[:, None]
    kc0, cc = can_spring(mc, _field(fx.f_can, shape)[:, None], _field(fx.zeta_can, shape)[:, None])
    w2, w3, w4, m2 = w**2, w**3, w**4, m**2  # powers taken once (the same values as inline)
    kc, kc1 = kc0 + 1j * w * cc, 1j * cc + z
    a, a1, a2 = kc - w2 * (mc + m), kc1 - 2 * w * (mc + m), -2 * (mc + m) + z
    a_sq, a_cube, a1_sq = a**2, a**3, a1**2
    mu = m * w2 + m2 * w4 / a
    mu1 = 2 * m * w + m2 * (4 * w3 / a - w4 * a1 / a_sq)
    mu2 = 2 * m + m2 * (12 * w2 / a - 8 * w3 * a1 / a_sq - w4 * a2 / a_sq + 2 * w4 * a1_sq / a_cube)
    F = -m * kc / a
    F1 = -m * (kc1 / a - kc * a1 / a_sq)
    F2 = -m * (-2 * kc1 * a1 / a_sq - kc * a2 / a_sq + 2 * kc * a1_sq / a_cube)
    return mu, mu1, mu2, F, F1, F2


def _looped(model: MinistackModel) -> bool:
    """Whether a voltage drive's shaker loop holds the model's neighbouring mode (`structure.Neighbour`, (N1))."""
    return model.neighbour is not None and model.neighbour.looped


def _neighbour(model: MinistackModel, shape) -> Neighbour:
    """The model's neighbouring mode with its fields as (P, 1) arrays."""
    return model.neighbour.batched(lambda v: _field(v, shape)[:, None])


def _loop_derivs(model: MinistackModel, w: NDArray, shape) -> tuple[NDArray, ...]:
    """`_derivs` of a rigid base with the shaker's loop around a neighbouring mode (`Neighbour.loop`, (N2)):
    mu = m w^2 (1 - delta), F = -gamma m / kappa, their w-derivatives by central differences (step 1e-4 w; the
    neighbour's half-power width is 2 zeta_n = 2% of its frequency, so the truncation is about 1e-4
    of the second derivative's)."""
    if model.fixture is not None:
        raise ValueError("a neighbouring mode in a shaker's loop is a voltage-driven structure's (the modal model "
                         "kind); the Ministack's fixture model has no such loop.")
    m = _field(model.m, shape)[:, None]
    nb = _neighbour(model, shape)

    def terms(x):
        gamma, delta = nb.loop(x / (2 * np.pi))
        return m * x**2 * (1.0 - delta), -m * gamma / nb.kappa

    h = 1e-4 * w
    (mu, F), (mu_p, F_p), (mu_m, F_m) = terms(w), terms(w + h), terms(w - h)
    return (mu, (mu_p - mu_m) / (2 * h), (mu_p - 2 * mu + mu_m) / h**2,
            F, (F_p - F_m) / (2 * h), (F_p - 2 * F + F_m) / h**2)


def _linearised(D: NDArray, Ks: NDArray, Z0: NDArray):
    """The solver of D v + Z0 Ks Re(conj(Z0) v) / |Z0|^2 = rhs (the balance linearised about Z0):
    a function rhs -> v, its coefficients computed once for the several right-hand sides."""
    Dr, Di, Kr, Ki = D.real, D.imag, Ks.real, Ks.imag  # v = Z0 u: D u + Ks Re(u) = p, two real equations
    DK, DiK = Dr + Kr, Di + Ki
    det = DK * Dr + Di * DiK

    def solve(rhs: NDArray) -> NDArray:
        p = rhs / Z0
        a = (p.real * Dr + Di * p.imag) / det
        b = (DK * p.imag - DiK * p.real) / det
        return Z0 * (a + 1j * b)

    return solve


def _quasi_steady(model: MinistackModel, f: NDArray, base_g: NDArray, rate: NDArray, dlog: NDArray,
                  direction: str, joint: tuple | None = None,
                  segments: Sequence[tuple[int, int, str]] | None = None) -> tuple[NDArray, NDArray, NDArray]:
    """(R, Z, A): slug acceleration envelope (in/s^2), joint envelope Z_0 + Z_1 (in), base (in/s^2), (P, N).

    joint : the model's `_joint_terms` when already at hand (they do not depend on the frequencies).
    segments : (start, stop, direction) of several runs laid end to end along f, each continued on its
    own (`envelope.sweep_amplitudes`; direction is then unused); None: f is one run.
    Every other step is elementwise in the frames, so a run's values do not depend on its neighbours."""
    shape, _ = _batch_shape(model, f.shape)
    P, N = shape
    w = 2 * np.pi * f
    A = np.broadcast_to(np.asarray(base_g, float), f.shape) * G
    m = _field(model.m, shape)
    joint = _joint_terms(model, shape) if joint is None else joint
    mu, mu1, mu2, F, F1, F2 = _derivs(model, w, shape)
    gamma = None if model.fixture is None and not _looped(model) else -F / m[:, None]
    mu_joint = mu if gamma is not None else mu.real
    s, _, kre, kim = _amplitudes(f, A, direction, shape, joint, m, mu_joint, gamma, segments)
    q = np.exp(s)
    Kz = kre + 1j * kim
    D = Kz - mu
    Z0 = F * A / D
    slopes = np.empty((6, P, N))
    _k.stiffness_slopes(q, w, *joint, _NODES, _WEIGHTS, slopes)
    Ks, dKw = slopes[2] + 1j * slopes[3], 1j * slopes[4]
    C, C1 = slopes[4], slopes[5]  # dIm K_z / domega (the dashpots turn the envelope's rate into force), its slope
    alpha = 2 * np.pi * np.broadcast_to(np.asarray(rate, float), f.shape)
    dlog = np.asarray(dlog)
    dl = np.broadcast_to(dlog.real.astype(float), f.shape)  # dlog|A|/dt
    dpsi = np.broadcast_to(dlog.imag.astype(float), f.shape) if np.iscomplexobj(dlog) else None  # dpsi/dt
    with np.errstate(all="ignore"):
        linearised = _linearised(D, Ks, Z0)
        dZ0 = alpha * linearised(F1 * A - (dKw - mu1) * Z0) + dl * linearised(F * A)
        Q = (-(1j * mu1 + C) * dZ0 - 0.5j * alpha * mu2 * Z0 - 0.5 * alpha * C1 * Z0 - 1j * F1 * A * dl
             - 0.5j * alpha * F2 * A)
        if dpsi is not None:  # the drive turning in phase: Z_0 turns with it (i psi' Z_0), and -i F' A' gains F' psi' A
            dZ0 = dZ0 + 1j * dpsi * Z0
            Q = Q - (1j * mu1 + C) * 1j * dpsi * Z0 + F1 * A * dpsi
        Z1 = linearised(Q)
        size = np.abs(Z1)
        Z1 = np.where(size > CAP * q, Z1 * CAP * q / size, Z1)
        Z1 = np.where(np.isfinite(Z1), Z1, 0.0)
    force = Kz * (Z0 + Z1) + Z0 * Ks * np.real(np.conj(Z0) * Z1) / q**2 + C * dZ0 + 0.5 * alpha * C1 * Z0
    return -force / m[:, None], Z0 + Z1, np.broadcast_to(A, (P, N))


def _sensor(model: MinistackModel, f: NDArray, shape) -> NDArray:
    gain = _field(model.sensor_gain, shape)[:, None]
    tau = _field(model.sensor_delay_s, shape)[:, None]
    return gain * np.exp(-2j * np.pi * f * tau)


def _channel(model: MinistackModel, T: NDArray, f: NDArray, shape) -> NDArray:
    """What the response channel reads of the slug's absolute T = R / A (P, N): a neighbouring mode added
    (linear, steady), then the sensor's gain and delay. In a shaker's loop (`Neighbour.loop`, (N2)) the
    mode's relative acceleration is (T - g) / (1 - delta), g = gamma / kappa (the slug's balance
    m w^2 (1 - delta) Z = K_z Z - F A, F = -g m: R = -K_z Z / m), and the channel reads
    1 + gamma (that + N' / kappa)."""
    if model.neighbour is not None:
        nb = _neighbour(model, shape)
        if nb.looped:
            gamma, delta = nb.loop(f)
            T = 1.0 + gamma * ((T - gamma / nb.kappa) / (1.0 - delta) + nb.frf(f) / nb.kappa)
        else:
            T = T + nb.frf(f)
    return T * _sensor(model, f, shape)


def quasi_steady(model: MinistackModel, f_hz: ArrayLike, base_g: ArrayLike = 1.0, *,
                 rate_hz_per_s: ArrayLike = 0.0, dlog_base_per_s: ArrayLike = 0.0,
                 direction: Literal["up", "down"] = "up") -> NDArray[np.complex128]:
    """Transmissibility a sweep shows, to first order in its rate (see the module notes).

    Parameters
    ----------
    model : MinistackModel
        As `steady_state` (fields may be batched (P, 1)).
    f_hz : array_like, shape (N,)
        Drive frequencies, Hz.
    base_g : float or array_like, shape (N,)
        Base-acceleration amplitude, g.
    rate_hz_per_s : float or array_like, shape (N,)
        Signed sweep rate df/dt at each frequency, Hz/s (negative sweeping down).
    dlog_base_per_s : float or array_like, shape (N,)
        Rate of the base amplitude's logarithm, 1/s (a ramp).
    direction : {'up', 'down'}
        The branch the sweep follows (`steady_state`).

    Returns
    -------
    ndarray of complex, shape broadcast(parameter shape, (N,))
        Response over base, sensor gain and delay applied.
    """
    f = np.atleast_1d(np.asarray(f_hz, dtype=float))
    shape, out_shape = _batch_shape(model, f.shape)
    R, _, A = _quasi_steady(model, f, np.broadcast_to(np.asarray(base_g, float), f.shape),
                            rate_hz_per_s, dlog_base_per_s, direction)
    return _channel(model, R / A, f, shape).reshape(out_shape)


def quasi_steady_runs(model: MinistackModel, runs: Sequence[tuple]) -> list[NDArray[np.complex128]]:
    """`quasi_steady` of one model (one parameter set or a batch) along several runs' frames.

    runs : one (f_hz (N,), base_g (N,), rate_hz_per_s, dlog_base_per_s, direction) per run, as
    `quasi_steady`'s arguments. The runs are laid end to end and evaluated in one pass (each
    continued along its own sweep); each run's result equals `quasi_steady`'s bit for bit.
    """
    f = [np.atleast_1d(np.asarray(r[0], dtype=float)) for r in runs]
    ends = np.cumsum([0, *(x.size for x in f)])
    segments = [(int(a), int(b), r[4]) for a, b, r in zip(ends[:-1], ends[1:], runs)]
    f_all = np.concatenate(f)
    base, rate = (np.concatenate([np.broadcast_to(np.asarray(r[i], float), x.shape) for r, x in zip(runs, f)])
                  for i in (1, 2))
    dtype = complex if any(np.iscomplexobj(r[3]) for r in runs) else float  # a drive turning in phase: complex
    dlog = np.concatenate([np.broadcast_to(np.asarray(r[3], dtype), x.shape) for r, x in zip(runs, f)])
    shape, out_shape = _batch_shape(model, f_all.shape)
    R, _, A = _quasi_steady(model, f_all, base, rate, dlog, "up", segments=segments)
    T = _channel(model, R / A, f_all, shape).reshape(out_shape)
    return [T[..., a:b] for a, b, _ in segments]
