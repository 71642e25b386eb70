"""The swept envelope through the resonance: the slow flow integrated (see `jointcal.models.swept`).

`swept_transmissibility` integrates the first-order slow flow of `jointcal.models.swept` by
RK4 (`_envelope_kernel.slow_flow`) through the resonance, from the quasi-steady state at
x = -`run_in` (x = (f / f_res - 1) / zeta, in sweep order; `SPAN` for eta up to about 4, further back for a
faster sweep, whose start state has less time to die out) to x = max(`SPAN`, 1.2 eta), and
averages it over each frame's Hann window as the envelopes are (T = <R> / <A>); other
frames take `quasi_steady`. A drive with a phase (`SweepDrive.phase_rad`) is integrated as its
complex envelope A = |A| e^{i psi}: the forcing F A - i F' A' - (i/2) alpha F'' A with
A' = A (dlog|A|/dt + i dpsi/dt), the start state turned by e^{i psi}, and <A> complex.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _envelope_kernel as _k
from ..units import G
from .envelope import GAUSS_NODES, GAUSS_WEIGHTS, batch_field, joint_terms
from .structure import MinistackModel
from .swept import SweepDrive, _channel, _derivs, _quasi_steady, sweep_eta

__all__ = ["swept_transmissibility", "run_in", "ETA_MIN", "SPAN", "START_TOL"]

ETA_MIN = 0.02  # below this eta the first-order quasi-steady envelope is as close as the integrated one
SPAN = 3.0  # integrated from x = -SPAN through the resonance, half-power half-widths
START_TOL = 1e-3  # the start state's relative error left at the resonance (`run_in`)
STEP = 0.4  # RK4 step: STEP / (largest |x| + 1) of the decay time 1 / (2 pi f_res zeta)


def swept_transmissibility(model: MinistackModel, drive: SweepDrive, t_s: ArrayLike, *, f_res_hz: float,
                           zeta: float, span: float = SPAN) -> NDArray[np.complex128]:
    """Transmissibility at frames t_s of one run, the sweep's transient integrated (one parameter set).

    Parameters
    ----------
    model : MinistackModel
        Scalar fields (one parameter set).
    drive : SweepDrive
        The run's measured drive (frame times, frequency, base amplitude, window).
    t_s : array_like, shape (n,)
        Frames wanted (centre times, s, within the drive's span).
    f_res_hz, zeta : float
        Where the resonance is (the measured one) and its damping ratio: the integration
        covers x = (f / f_res - 1) / zeta from -span to max(span, 1.2 eta) in sweep order.
    span : float
        Half-power half-widths integrated before (and at least after) the resonance.

    Returns
    -------
    ndarray of complex, shape (n,)
        Response over base as the envelopes show it (sensor gain and delay applied).

    Notes
    -----
    Runs with eta below `ETA_MIN` take `quasi_steady` at every frame.
    """
    t_out = np.atleast_1d(np.asarray(t_s, dtype=float))
    f_o, b_o, r_o, dl_o = drive.at(t_out)
    rate = _rate_at(drive, f_res_hz)
    direction = "up" if rate >= 0 else "down"
    R, _, A = _quasi_steady(model, f_o, b_o, r_o, dl_o, direction)
    T = (R / A)[0]
    eta = sweep_eta(rate, f_res_hz, zeta)
    sign = 1.0 if rate >= 0 else -1.0
    after = max(span, 1.2 * eta)
    before = run_in(eta, span)
    x = sign * (drive.f_hz / f_res_hz - 1.0) / zeta
    inside = np.flatnonzero((x >= -before) & (x <= after))
    L = drive.window_s
    if eta >= ETA_MIN and inside.size:
        ka = int(np.searchsorted(drive.t_s, drive.t_s[inside[0]] - L, side="right")) - 1
        ka = max(ka, 0)
        t_a = drive.t_s[ka]
        t_b = min(drive.t_s[-1], drive.t_s[inside[-1]] + L)
        keep = (t_out - L / 2 >= t_a) & (t_out + L / 2 <= t_b)
        if keep.any():
            T[keep] = _integrated(model, drive, t_a, t_b, ka, t_out[keep], direction,
                                  2 * np.pi * f_res_hz * zeta, max(before, after))
    return _channel(model, T[None], f_o, (1, t_out.size))[0]


def run_in(eta: float, span: float = SPAN, tol: float = START_TOL) -> float:
    """Half-power half-widths before the resonance where the integration starts: the smallest x >= span at
    which the quasi-steady start state, wrong by about its own first-order term eta / (2 pi x^2), has decayed
    to `tol` by the resonance, eta / (2 pi x^2) exp(-2 pi x / eta) <= tol (the sweep takes x / eta decay
    times 1 / (2 pi f zeta) to get there). span for slow sweeps (eta below about 4); a fast sweep is
    integrated from further back, from the drive's start when it is closer."""
    if eta <= 0.0:
        return span
    x = np.geomspace(span, 1e6, 2000)
    ok = eta / (2 * np.pi * x**2) * np.exp(-2 * np.pi * x / eta) <= tol
    return float(x[np.argmax(ok)]) if ok.any() else float(x[-1])


def _rate_at(drive: SweepDrive, f_res_hz: float) -> float:
    """The sweep rate (Hz/s) where the drive crosses f_res: the median over the frames within a window of the
    crossing (the drive's rate elsewhere, e.g. a log sweep's, does not set eta)."""
    r = drive.rates[0]
    t_res = drive.t_s[int(np.argmin(np.abs(drive.f_hz - f_res_hz)))]
    near = np.abs(drive.t_s - t_res) <= drive.window_s
    return float(np.median(r[near])) if near.sum() >= 3 else float(np.median(r))


def _integrated(model: MinistackModel, drive: SweepDrive, t_a: float, t_b: float, ka: int, t_out: NDArray,
                direction: str, gamma: float, x_max: float) -> NDArray[np.complex128]:
    """<R> / <A> over the Hann window of each frame t_out, the slow flow integrated over [t_a, t_b]."""
    r_d, dl_d = drive.rates
    _, Z, _ = _quasi_steady(model, drive.f_hz[:ka + 1], drive.base_g[:ka + 1], r_d[:ka + 1], dl_d[:ka + 1],
                            direction)
    h = STEP / ((x_max + 1.0) * gamma)
    n = int(np.ceil((t_b - t_a) / h)) + 1
    h = (t_b - t_a) / (n - 1)
    th = t_a + 0.5 * h * np.arange(2 * n - 1)
    f, b, r, dl = drive.at(th)
    w = 2 * np.pi * f
    alpha = 2 * np.pi * r
    A = b * G
    z0 = complex(Z[0, -1])
    if drive.phase_rad is not None:  # the complex drive |A| e^{i psi}; the state starts turned with it
        A = A * np.exp(1j * drive.phase_at(th))
        z0 = z0 * np.exp(1j * drive.phase_rad[ka])
    mu, mu1, mu2, F, F1, F2 = (v[0] for v in _derivs(model, w, (1, w.size)))
    p0 = np.ascontiguousarray(-mu + 0.5j * alpha * mu2)
    g0 = np.ascontiguousarray(F * A - 1j * F1 * A * dl - 0.5j * alpha * F2 * A)
    m1 = np.ascontiguousarray(1j * mu1 + 0j)
    *scalars, codes, coefs = joint_terms(model, (1, 1))
    joint = (*(float(v[0]) for v in scalars), codes, np.ascontiguousarray(coefs[0]))
    force = np.empty(n, complex)
    _k.slow_flow(z0, h, w, alpha, p0, g0, m1, *joint, GAUSS_NODES, GAUSS_WEIGHTS, force)
    m = float(batch_field(model.m, (1, 1))[0])
    tn, Rn, An = th[::2], -force / m, A[::2]
    L = drive.window_s
    out = np.empty(t_out.size, complex)
    for i, tc in enumerate(t_out):  # the envelopes' periodic Hann window, centred on the frame
        j0, j1 = np.searchsorted(tn, [tc - L / 2, tc + L / 2])
        wgt = np.sin(np.pi * (tn[j0:j1] - (tc - L / 2)) / L) ** 2
        out[i] = np.sum(wgt * Rn[j0:j1]) / np.sum(wgt * An[j0:j1])
    return out
