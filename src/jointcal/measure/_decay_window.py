"""One window of a free decay: a damped sinusoid whose decay rate and frequency drift linearly over it.

    x(t) = exp(-sigma t - s t^2 / 2) (a cos(w t + r t^2 / 2) + b sin(w t + r t^2 / 2)),

t centred on the window, so sigma and w are the decay rate and frequency at its centre. A jointed
mode's decay rate and frequency change along the decay; a window model with constant ones reads them
biased by the coupling of their drift with the window's own phase and with the decay's weight (on
the virtual Ministack: +-1% in zeta from window to window at 3 periods, -1.5% at 20 periods read at
the weighted centroid); the drift terms r and s take that up, and cost sigma's standard error little,
since t^2 is nearly orthogonal to t over a window. Variable projection: a and b by linear least
squares, (w, sigma, r, s) by Gauss-Newton with step halving, started from the constant model's fit.

The drifts are still one order short where a window spans e-folds of a decay whose rate and frequency
follow its amplitude: the log-envelope's t^3 term projects onto its slope (t^3 is odd, as t is). A caller
that knows the third-order terms (from the neighbouring windows: `jointcal.measure.ringdown._cubic_terms`)
holds them fixed (`cubic`), which costs no parameter; the t^4 terms left are even and do not bias the slope.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["fit_window", "fit_drifts"]


@njit(cache=True)
def _project(p: NDArray, t: NDArray, x: NDArray, c0: float, c1: float):
    """a, b, the model, d(model)/d(phase) and the basis B (n, 2) at the nonlinear parameters p (w, sigma, r, s),
    the phase's and the log-envelope's third-order terms c0, c1 held."""
    n = t.size
    B = np.empty((n, 2))
    env = np.empty(n)
    ph = np.empty(n)
    for i in range(n):
        ti = t[i]
        t3 = ti * ti * ti
        env[i] = np.exp(-p[1] * ti - 0.5 * p[3] * ti * ti + c1 * t3)
        ph[i] = p[0] * ti + 0.5 * p[2] * ti * ti + c0 * t3
        B[i, 0] = env[i] * np.cos(ph[i])
        B[i, 1] = env[i] * np.sin(ph[i])
    ab = np.linalg.lstsq(B, x)[0]
    a, b = ab[0], ab[1]
    m = B[:, 0] * a + B[:, 1] * b
    dm = env * (-a * np.sin(ph) + b * np.cos(ph))
    return a, b, m, dm, B


@njit(cache=True)
def _gauss_newton(p: NDArray, t: NDArray, x: NDArray, free: int, c0: float, c1: float, iters: int = 40):
    """Minimise |x - model|^2 over the first `free` of (w, sigma, r, s), step halving on an increase."""
    a, b, m, dm, B = _project(p, t, x, c0, c1)
    cost = np.sum((x - m) ** 2)
    n = t.size
    for _ in range(iters):
        J = np.empty((n, free))
        for i in range(n):
            cols = (t[i] * dm[i], -t[i] * m[i], 0.5 * t[i] * t[i] * dm[i], -0.5 * t[i] * t[i] * m[i])
            for j in range(free):
                J[i, j] = cols[j]
        scale = np.sqrt(np.sum(J * J, axis=0))
        for j in range(free):
            if scale[j] == 0.0:
                scale[j] = 1.0
        sol = np.linalg.lstsq(J / scale, x - m)[0] / scale
        step = np.zeros(4)
        step[:free] = sol
        lam = 1.0
        accepted = False
        while lam > 1e-4:
            ta, tb, tm, tdm, tB = _project(p + lam * step, t, x, c0, c1)
            new = np.sum((x - tm) ** 2)
            if new <= cost:
                accepted = True
                break
            lam /= 2
        if not accepted:
            break
        done = cost - new <= 1e-12 * cost
        p = p + lam * step
        a, b, m, dm, B, cost = ta, tb, tm, tdm, tB, new
        if done:
            break
    return p, a, b, m, dm, B


def fit_window(t: NDArray, x: NDArray, w0: float, sigma0: float = 0.0, *,
               cubic: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float, complex, float, float, float]:
    """Fit one window of a decay.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times, s, centred on the window (t = 0 at its centre).
    x : ndarray, shape (n,)
        The band-passed response (any unit).
    w0 : float
        Starting frequency, rad/s.
    sigma0 : float
        Starting decay rate, 1/s.
    cubic : (float, float)
        Known third-order terms of the phase and of the log-envelope, (rad/s^3, 1/s^3): the model's
        phase gains cubic[0] t^3 and its log-envelope cubic[1] t^3, held fixed (not fitted).

    Returns
    -------
    w : float
        Frequency at the window's centre, rad/s (the damped one).
    sigma : float
        Decay rate at the window's centre, 1/s.
    c : complex
        a + i b: the amplitude and phase at the centre (x's unit).
    misfit : float
        Relative rms residual: rms(x - model) / (|c| / sqrt 2).
    se_sigma : float
        Standard error of sigma per unit white-noise rms: sqrt of (J^T J)^-1's sigma entry over all six
        parameters (multiply by the noise's rms).
    se_w : float
        The same for w, rad/s per unit white-noise rms.
    """
    p, a, b, m, dm, B = _fit(t, x, w0, sigma0, cubic)
    J = np.column_stack([t * dm, -t * m, 0.5 * t * t * dm, -0.5 * t * t * m, B])
    try:
        cov = np.linalg.inv(J.T @ J)
        se, se_w = float(np.sqrt(cov[1, 1])), float(np.sqrt(cov[0, 0]))
    except np.linalg.LinAlgError:
        se = se_w = np.inf
    return float(p[0]), float(p[1]), complex(a, b), _misfit(x, m, a, b), se, se_w


def fit_drifts(t: NDArray, x: NDArray, w0: float) -> tuple[NDArray, complex, float]:
    """`fit_window`'s fit, its drifts too: p = (w, sigma, r, s) (rad/s, 1/s, rad/s^2, 1/s^2) at the window's
    centre, c = a + i b and the relative rms misfit (the decay's continuation, `jointcal.measure.ringdown`)."""
    p, a, b, m, _, _ = _fit(t, x, w0, 0.0, (0.0, 0.0))
    return p, complex(a, b), _misfit(x, m, a, b)


def _fit(t, x, w0, sigma0, cubic):
    """The constant model's fit, then the drifting one's from it (the numba kernels above)."""
    t, x = np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(x, dtype=float)
    c0, c1 = float(cubic[0]), float(cubic[1])
    p, *_ = _gauss_newton(np.array([float(w0), float(sigma0), 0.0, 0.0]), t, x, 2, c0, c1)
    return _gauss_newton(p, t, x, 4, c0, c1)


def _misfit(x, m, a, b) -> float:
    return float(np.sqrt(np.mean((x - m) ** 2)) / max(np.hypot(a, b) / np.sqrt(2), 1e-300))
