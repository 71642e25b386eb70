"""One window of a free decay: a damped sinusoid whose decay rate and frequency drift linearly over it.

    x(t) = exp(-sigma t - s t^2 / 2) (a cos(w t + r t^2 / 2) + b sin(w t + r t^2 / 2)),

t centred on the window, so sigma and w are the decay rate and frequency at its centre. A jointed
mode's decay rate and frequency change along the decay; a window model with constant ones reads them
biased by the coupling of their drift with the window's own phase and with the decay's weight (on
the virtual Ministack: +-1% in zeta from window to window at 3 periods, -1.5% at 20 periods read at
the weighted centroid); the drift terms r and s take that up, and cost sigma's standard error little,
since t^2 is nearly orthogonal to t over a window. Variable projection: a and b by linear least
squares, (w, sigma, r, s) by Gauss-Newton with step halving on the projected functional, started from the
constant model's fit. The Gauss-Newton matrix is Kaufman's: the model's derivatives at a, b held, less their
part in the span of the basis that a and b take up at once (Golub and Pereyra, Inverse Problems 19, 2003).
Without that projection the step ignores how a and b follow (w, sigma): the iteration crawled to its cap
of 40 on a 1500-sample window that the projected step fits in 3 to 5, and stopped far from the optimum on
windows with strong drifts (tests/benchmarks/bench_decay_window.py: 7.3 -> 0.6 ms per window).

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
    the phase's and the log-envelope's third-order terms c0, c1 held. a and b solve the 2 x 2 normal equations
    of B (its two columns a cosine and a sine under one envelope: near orthogonal over a window)."""
    n = t.size
    B = np.empty((n, 2))
    env = np.empty(n)
    g00 = g01 = g11 = r0 = r1 = 0.0
    for i in range(n):
        ti = t[i]
        t3 = ti * ti * ti
        env[i] = np.exp(-p[1] * ti - 0.5 * p[3] * ti * ti + c1 * t3)
        ph = p[0] * ti + 0.5 * p[2] * ti * ti + c0 * t3
        B[i, 0] = env[i] * np.cos(ph)
        B[i, 1] = env[i] * np.sin(ph)
        g00 += B[i, 0] * B[i, 0]
        g01 += B[i, 0] * B[i, 1]
        g11 += B[i, 1] * B[i, 1]
        r0 += B[i, 0] * x[i]
        r1 += B[i, 1] * x[i]
    det = g00 * g11 - g01 * g01
    if det > 1e-12 * g00 * g11:
        a, b = (g11 * r0 - g01 * r1) / det, (g00 * r1 - g01 * r0) / det
    else:  # a degenerate basis (a window too short for its frequency): the least-norm solution
        ab = np.linalg.lstsq(B, x)[0]
        a, b = ab[0], ab[1]
    m = np.empty(n)
    dm = np.empty(n)
    for i in range(n):
        m[i] = B[i, 0] * a + B[i, 1] * b
        dm[i] = -a * B[i, 1] + b * B[i, 0]  # env (-a sin + b cos)
    return a, b, m, dm, B


@njit(cache=True)
def _gauss_newton(p: NDArray, t: NDArray, x: NDArray, free: int, c0: float, c1: float, iters: int = 40):
    """Minimise |x - model|^2 over the first `free` of (w, sigma, r, s), step halving on an increase."""
    a, b, m, dm, B = _project(p, t, x, c0, c1)
    cost = np.sum((x - m) ** 2)
    n = t.size
    for _ in range(iters):
        # Gauss-Newton on the projected functional (Kaufman's variable projection): the model's derivatives in
        # (w, sigma, r, s) at a, b held, less their part in span(B) that a and b take up; with
        # C = J^T J, E = J^T B, G = B^T B the normal matrix is C - E G^-1 E^T, and J^T r needs no projection
        # (r is orthogonal to B at a, b).
        A = np.zeros((free, free))
        E = np.zeros((free, 2))
        g = np.zeros(free)
        G = np.zeros((2, 2))
        col = np.empty(4)
        for i in range(n):
            ti = t[i]
            col[0], col[1] = ti * dm[i], -ti * m[i]
            col[2], col[3] = 0.5 * ti * ti * dm[i], -0.5 * ti * ti * m[i]
            ri = x[i] - m[i]
            G[0, 0] += B[i, 0] * B[i, 0]
            G[0, 1] += B[i, 0] * B[i, 1]
            G[1, 1] += B[i, 1] * B[i, 1]
            for j in range(free):
                g[j] += col[j] * ri
                E[j, 0] += col[j] * B[i, 0]
                E[j, 1] += col[j] * B[i, 1]
                for k in range(j + 1):
                    A[j, k] += col[j] * col[k]
        det = G[0, 0] * G[1, 1] - G[0, 1] * G[0, 1]
        if det > 1e-12 * G[0, 0] * G[1, 1]:
            for j in range(free):
                e0 = (G[1, 1] * E[j, 0] - G[0, 1] * E[j, 1]) / det  # (G^-1 E^T)[:, j]
                e1 = (G[0, 0] * E[j, 1] - G[0, 1] * E[j, 0]) / det
                for k in range(j + 1):
                    A[j, k] -= E[k, 0] * e0 + E[k, 1] * e1
        scale = np.empty(free)
        for j in range(free):
            scale[j] = np.sqrt(A[j, j]) if A[j, j] > 0.0 else 1.0
        for j in range(free):
            for k in range(j + 1):
                A[j, k] /= scale[j] * scale[k]
                A[k, j] = A[j, k]
        sol = np.linalg.lstsq(A, g / scale)[0] / scale
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
