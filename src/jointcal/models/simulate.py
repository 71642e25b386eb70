"""Swept-sine time integration of the base-excited Ministack model.

`simulate` drives a `MinistackModel` with a base-acceleration history (measured or
synthetic) and returns the response accelerometer's signal at the input samples.
The joint force is the exact Iwan hysteresis (turning-point rules, no sliders); the
linear structure is propagated exactly (zero natural-frequency error at any step);
see `jointcal.models._integrator` for the scheme. `integrate` runs the same scheme on any
linear system with one joint DOF (e.g. a structure coupled to a shaker,
`jointcal.synth.shaker`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import expm

from collections.abc import Callable, Sequence

from . import _integrator
from ..units import G
from ._masing import kernel_constants
from .elements import CONTACT_SPRING, Element, element_table
from .iwan import IwanParams, derived
from .structure import MinistackModel, Neighbour, StateSpace, state_space

__all__ = ["SimResult", "simulate", "integrate", "hermite_propagator", "fractional_delay", "substeps",
           "band_limited"]


@dataclass(frozen=True)
class SimResult:
    """response_g: response channel (g); z_in: joint relative displacement (in); n_sub: substeps per sample."""

    response_g: NDArray[np.float64]
    z_in: NDArray[np.float64]
    n_sub: int


def hermite_propagator(A: NDArray, b: NDArray, h: float):
    """Exact one-step maps for x' = A x + b p(t), p a cubic Hermite over [0, h].

    Returns Phi = expm(A h) and G (n, 4) such that
    x(h) = Phi x(0) + G @ [p(0), h p'(0), p(h), h p'(h)].
    Uses phi-functions from one augmented matrix exponential.
    """
    n = A.shape[0]
    W = np.zeros((n + 4, n + 4))
    W[:n, :n] = A * h
    W[:n, n] = b * h
    W[n:n + 3, n + 1:n + 4] = np.eye(3)
    E = expm(W)
    Phi = E[:n, :n]
    phis = E[:n, n:n + 4]  # phi_1..phi_4 (A h) (b h)
    g0, g1, g2, g3 = phis[:, 0], phis[:, 1], 2.0 * phis[:, 2], 6.0 * phis[:, 3]  # int e^{A(h-s)} b (s/h)^j ds
    Gm = np.column_stack([g0 - 3 * g2 + 2 * g3, g1 - 2 * g2 + g3, 3 * g2 - 2 * g3, g3 - g2])
    return Phi, Gm


def substeps(model: MinistackModel, fs: float, omega_h: float = 0.65) -> int:
    """Substeps per input sample so that omega_0 h <= omega_h at the stuck-joint frequency.

    With a unilateral contact the frequency is the closed contact's, and the step is a
    quarter of that: the contact force has a kink the step's cubic Hermite force does not
    follow (measured on a bilinear oscillator at omega_2 h = 0.5: 27% amplitude lost over
    700 undamped cycles; at omega_2 h = 0.13, 0.08%).
    """
    kc = sum(float(e.a) for e in model.elements if e.code == CONTACT_SPRING)
    if kc > 0:
        w = np.sqrt((model.k + model.KT + kc) / model.m)
        return max(1, int(np.ceil(4.0 * w / (omega_h * fs))))
    return max(1, int(np.ceil(2 * np.pi * model.f0_hz / (omega_h * fs))))


def _substep_maps(Gu: NDArray, n_sub: int):
    """Input maps per substep of a parent sample interval (see `_integrator.run`).

    Over the parent interval the input is the cubic Hermite through the samples; its
    value and h-scaled rate at substep nodes tau_j = j/n_sub are linear in the parent
    data [u_k, H u'_k, u_k+1, H u'_k+1], so each substep's input map is Gu @ W_j.
    """
    tau = np.arange(n_sub + 1) / n_sub
    val = np.stack([1 - 3 * tau**2 + 2 * tau**3, tau - 2 * tau**2 + tau**3,
                    3 * tau**2 - 2 * tau**3, tau**3 - tau**2], axis=1)
    der = np.stack([-6 * tau + 6 * tau**2, 1 - 4 * tau + 3 * tau**2,
                    6 * tau - 6 * tau**2, 3 * tau**2 - 2 * tau], axis=1) / n_sub
    W = np.stack([val[:-1], der[:-1], val[1:], der[1:]], axis=1)  # (n_sub, 4, 4)
    Gsub = np.ascontiguousarray(np.einsum("ic,jcd->jid", Gu, W))
    return Gsub, np.ascontiguousarray(val[1:])


def fractional_delay(x: ArrayLike, tau: float, fs: float) -> NDArray[np.float64]:
    """Delay a sampled signal by tau seconds (any fraction of a sample), exactly in frequency.

    The record is zero-padded before the FFT phase shift so nothing wraps around.
    """
    x = np.asarray(x, dtype=float)
    if tau == 0.0:
        return x.copy()
    n = x.size
    pad = int(np.ceil(abs(tau) * fs)) + 16
    nfft = 1 << int(np.ceil(np.log2(n + 2 * pad)))
    X = np.fft.rfft(x, nfft)
    f = np.fft.rfftfreq(nfft, 1.0 / fs)
    return np.fft.irfft(X * np.exp(-2j * np.pi * f * tau), nfft)[:n]


def band_limited(u: NDArray, fs: float, f_hz: float, samples_per_cycle: float = 12.0) -> tuple[NDArray, int]:
    """A sampled input reconstructed between its samples as the band-limited signal it is.

    Returns (u_up, U): the record resampled by the integer factor U that gives at least
    `samples_per_cycle` samples per cycle at `f_hz` (polyphase, Kaiser-windowed sinc:
    `scipy.signal.resample_poly`, zero phase, so sample k*U is input sample k), and U.
    A record sampled at a few samples per cycle (2.5 kHz at 10 kHz: 4) is band limited
    (anti-aliased) but not smooth between samples: the step's cubic Hermite through its
    values and finite-difference rates misses it by percents (measured: the exact model
    driven by a 10 kHz record read 0.2 dB low and 0.07% stiff at 2.4 kHz).
    """
    from scipy.signal import resample_poly  # here: scipy.signal (and the scipy.stats it loads) costs a stage
    # that never simulates 0.8 s of CPU at its start

    U = max(1, int(np.ceil(samples_per_cycle * f_hz / fs)))
    return (resample_poly(u, U, 1) if U > 1 else u), U


def simulate(model: MinistackModel, base_accel_g: ArrayLike, fs: float, *,
             n_sub: int | None = None, omega_h: float = 0.65,
             sliders: tuple[NDArray, NDArray] | None = None, samples_per_cycle: float | None = 12.0) -> SimResult:
    """Response of the model to a base-acceleration history.

    Parameters
    ----------
    model : MinistackModel
        Structure, joint and named effects.
    base_accel_g : array_like, shape (N,)
        Control-accelerometer signal, g, sampled at `fs`; the model starts at rest.
    fs : float
        Sample rate, Hz.
    n_sub : int, optional
        Integration substeps per sample; default from `substeps` with `omega_h`.
    omega_h : float
        Largest omega_0 * h allowed when choosing n_sub (rad). The linear part is exact
        at any step; this bounds the error of the joint's nonlinear force. Measured on
        the Table 3.2 joint at omega_0 h = 0.6: resonance frequency within 0.01% and
        phase-resonance damping within 0.4% of the converged (n_sub = 8) result.
    sliders : (k, phi), optional
        Replace the exact Iwan joint by Jenkins sliders (stiffness lbf/in, slip in),
        e.g. from `jointcal.models.sliders.slider_set`: a test reference only. The
        stuck stiffness is then the sliders' total, not model.iwan.KT.
    samples_per_cycle : float or None
        The record is treated as band limited and reconstructed between samples by
        polyphase resampling (`scipy.signal.resample_poly`) until it has at least this
        many samples per cycle of the stuck-joint frequency (`band_limited`);
        the substeps then divide the reconstructed interval. None: the cubic Hermite
        through the samples (exact for inputs that are cubic between samples).

    Returns
    -------
    SimResult
        Response-channel acceleration (g, with sensor gain and delay applied) and the
        joint displacement (in), both at the input samples; n_sub counts integration
        steps per input sample (reconstruction included).
    """
    u = np.ascontiguousarray(base_accel_g, dtype=float) * G
    if u.ndim != 1 or u.size < 2:
        raise ValueError("simulate: base_accel_g must be a 1-D record of at least 2 samples.")
    if not np.all(np.isfinite(u)):
        raise ValueError("simulate: base_accel_g holds NaN or inf; clean or trim the record first.")
    if not fs > 0:
        raise ValueError(f"simulate: sample rate must be positive, got {fs!r}.")
    n_out, u_in = u.size, u
    nb = model.neighbour
    if nb is not None and nb.looped and complex(nb.kappa) != 1.0:  # the mode's own drive: the read-out's / kappa
        u = np.ascontiguousarray(turned(u, 1.0 / complex(nb.kappa), fs))
    U = 1
    if samples_per_cycle is not None:
        u, U = band_limited(u, fs, model.f0_hz, samples_per_cycle)
        fs = fs * U
    n_sub = substeps(model, fs, omega_h) if n_sub is None else int(n_sub)
    Y, z = integrate(state_space(model), u, fs, n_sub, iwan=model.iwan, sliders=sliders, elements=model.elements)
    y = Y[0]
    if U > 1:
        y, z, fs = y[::U][:n_out].copy(), z[::U][:n_out].copy(), fs / U
    if nb is not None and nb.looped:  # in the state space: the channel reads the read-out's drive, not the mode's
        y = y - u[::U][:n_out] + u_in
    elif nb is not None:
        y = y + neighbour_response(nb, u_in, fs)
    if model.sensor_delay_s != 0.0:
        y = fractional_delay(y, model.sensor_delay_s, fs)
    y *= model.sensor_gain / G
    return SimResult(response_g=y, z_in=z, n_sub=n_sub * U)


def _through(u: NDArray, H: Callable[[NDArray], NDArray], fs: float) -> NDArray[np.float64]:
    """The record u (sampled at fs, Hz) through the frequency response H(f), line by line on its spectrum
    zero-padded to twice its length (a ringing does not wrap): exact for the band-limited record a DAQ
    takes, as the drive's gain is applied (`jointcal.validate.drive`)."""
    n = 1 << int(np.ceil(np.log2(2 * u.size)))
    return np.fft.irfft(np.fft.rfft(u, n) * H(np.fft.rfftfreq(n, 1.0 / fs)), n)[:u.size]


def turned(u: NDArray, factor: complex, fs: float) -> NDArray[np.float64]:
    """The record u (sampled at fs, Hz) with every line of its spectrum multiplied by the complex constant
    factor (its conjugate at negative frequencies): a gain and a phase shift, the same at every frequency
    (the mean, real, only scaled)."""
    return _through(u, lambda f: np.where(f > 0, factor, abs(factor)), fs)


def neighbour_response(nb: Neighbour, u: NDArray, fs: float) -> NDArray[np.float64]:
    """Relative acceleration of a neighbouring linear mode (`structure.Neighbour`) driven by the base
    acceleration u (any unit; the same out), sampled at fs (Hz): its FRF applied by `_through`."""
    return _through(u, nb.frf, fs)


def _joint(iwan: IwanParams | None, sliders: tuple[NDArray, NDArray] | None = None) -> tuple:
    """One joint's kernel columns (kind, KT, R, chi, phimax, Fs)."""
    if sliders is not None:
        return 2, float(np.sum(sliders[0])), 0.0, 0.5, 1.0, 0.0
    if iwan is None:
        return 0, 0.0, 0.0, 0.5, 1.0, 0.0
    phimax, R, _ = (float(a) for a in derived(iwan.Fs, iwan.KT, iwan.chi, iwan.beta))
    R, chi = kernel_constants(R, iwan.chi)
    return 1, float(iwan.KT), float(R), float(chi), phimax, float(iwan.Fs)


def _run_kernel(A: NDArray, bu: NDArray, BF: NDArray, LZ: NDArray, LV: NDArray, u: NDArray, fs: float, n_sub: int,
                joints: Sequence[tuple], outputs: Sequence[tuple[NDArray, float, ArrayLike]], *,
                sliders: tuple[NDArray, NDArray] | None = None, elements: Sequence[Element] = ()
                ) -> tuple[NDArray, NDArray]:
    """The kernel's arguments from the system's matrices, and its run (private to `integrate`, `integrate_joints`).

    BF (n, J), LZ, LV (J, n) as `jointcal.models.joints.integrate_joints`; joints: J `_joint` columns; outputs
    (c (n,), du, df (J,) or scalar); elements act on the first joint's DOF. Returns Y (n_outputs, N), Z (J, N).
    """
    u = np.ascontiguousarray(u, dtype=float)
    J = len(joints)
    h = 1.0 / fs / n_sub
    Phi, Gu = hermite_propagator(A, bu, h)
    Gf = np.ascontiguousarray(np.stack([hermite_propagator(A, BF[:, j], h)[1] for j in range(J)]))
    Gsub, Wub = _substep_maps(Gu, n_sub)
    lv0 = np.asarray(LV[0], dtype=float)
    maps = (1.0 / fs, Gsub, Wub, np.ascontiguousarray(Phi), Gf, np.ascontiguousarray(LZ, dtype=float),
            np.ascontiguousarray(LV, dtype=float), np.ascontiguousarray(lv0 @ A, dtype=float), float(lv0 @ bu),
            np.array([float(lv0 @ BF[:, j]) for j in range(J)]))
    outs = (np.ascontiguousarray(np.array([np.asarray(c, float) for c, _, _ in outputs])),
            np.array([float(d) for _, d, _ in outputs]),
            np.ascontiguousarray(np.array([np.broadcast_to(np.asarray(d, float), (J,)) for _, _, d in outputs])))
    kinds = (tuple(int(c[0]) for c in joints), *(tuple(float(c[i]) for c in joints) for i in range(1, 6)))
    sl = (np.zeros(0), np.zeros(0)) if sliders is None else \
        tuple(np.ascontiguousarray(a, dtype=float) for a in sliders)
    Y = np.empty((len(outputs), u.size))
    Z = np.empty((J, u.size))
    _integrator.run(u, _integrator.rate(u, fs), maps, outs, kinds, sl, element_table(elements), Y, Z)
    return Y, Z


def integrate(ss: StateSpace, u: NDArray, fs: float, n_sub: int, *, iwan: IwanParams | None = None,
              sliders: tuple[NDArray, NDArray] | None = None, elements: Sequence[Element] = (),
              outputs: Sequence[tuple[NDArray, float, float]] | None = None) -> tuple[NDArray, NDArray]:
    """Integrate x' = A x + bu u + bf r_nl from rest (the scheme of `jointcal.models._integrator`).

    Parameters
    ----------
    ss : StateSpace
        The linear system with the joint stuck (stiffness KT in A); z = lz.x is the joint DOF.
    u : ndarray, shape (N,)
        Input at the samples (the units of bu: in/s^2 for a base acceleration, V for a drive).
    fs : float
        Sample rate of u, Hz.
    n_sub : int
        Integration substeps per sample.
    iwan : IwanParams, optional
        The joint (exact Iwan hysteresis); None: no joint.
    sliders : (k, phi), optional
        Jenkins sliders in place of the Iwan joint (lbf/in, in): a test reference.
    elements : sequence of Element
        Nonlinear elements in parallel with the joint (`jointcal.models.elements`).
    outputs : sequence of (c (n,), du, df), optional
        Output channels y = c.x + du u + df r_nl; default the system's own (cy, dyu, dyf).

    Returns
    -------
    Y : ndarray, shape (n_outputs, N)
        The outputs at the samples.
    z : ndarray, shape (N,)
        The joint DOF at the samples.
    """
    outputs = [(ss.cy, ss.dyu, ss.dyf)] if outputs is None else list(outputs)
    Y, Z = _run_kernel(ss.A, ss.bu, np.asarray(ss.bf, dtype=float)[:, None], np.asarray(ss.lz)[None],
                       np.asarray(ss.lv)[None], u, fs, n_sub, [_joint(iwan, sliders)], outputs, sliders=sliders,
                       elements=elements)
    return Y, Z[0]
