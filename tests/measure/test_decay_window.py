"""One window of a free decay (jointcal.measure._decay_window): its variable-projection Gauss-Newton fit against
the closed form of a noise-free damped chirp, against a general nonlinear least-squares solver on noisy windows,
and its standard error against the scatter of repeated noisy fits."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from jointcal.measure._decay_window import fit_drifts, fit_window


def _window(n, fs, w, sigma, r, s, a=1.3, b=0.4):
    t = (np.arange(n) - (n - 1) / 2) / fs
    ph = w * t + 0.5 * r * t * t
    return t, np.exp(-sigma * t - 0.5 * s * t * t) * (a * np.cos(ph) + b * np.sin(ph))


def _model(q, t):
    w, sigma, r, s, a, b = q
    ph = w * t + 0.5 * r * t * t
    return np.exp(-sigma * t - 0.5 * s * t * t) * (a * np.cos(ph) + b * np.sin(ph))


@pytest.mark.parametrize("n", [60, 400, 3000])
def test_a_noise_free_damped_chirp_is_read_exactly(n):
    """x(t) = exp(-sigma t - s t^2/2) (a cos(w t + r t^2/2) + b sin(...)): the fit from a start 0.3% off in w and
    20% off in sigma returns w, sigma, r, s, a + ib of the closed form."""
    fs, w, sigma = 2048.0, 2 * np.pi * 97.0, 2 * np.pi * 97.0 * 0.012
    r, s = 0.002 * w * fs / n, 0.05 * sigma * fs / n  # drifts a few per cent of w, sigma over the window
    t, x = _window(n, fs, w, sigma, r, s)
    p, c, misfit = fit_drifts(t, x, w * 1.003)
    assert abs(p[0] / w - 1) < 1e-10 and abs(p[1] / sigma - 1) < 1e-8
    assert abs(p[2] / r - 1) < 1e-6 and abs(p[3] / s - 1) < 1e-5
    assert abs(c - (1.3 + 0.4j)) < 1e-8 and misfit < 1e-8
    w_, sig_, c_, mis_, se, se_w = fit_window(t, x, w * 1.003, sigma * 0.8)
    assert abs(w_ / w - 1) < 1e-10 and abs(sig_ / sigma - 1) < 1e-8 and mis_ < 1e-8


@pytest.mark.parametrize("seed", range(6))
def test_noisy_windows_reach_the_least_squares_optimum_of_a_general_solver(seed):
    """The full six-parameter least squares solved by scipy's Levenberg-Marquardt from the truth (tight
    tolerances): a cost no higher, and the same w and sigma to a thousandth of their standard errors."""
    rng = np.random.default_rng(seed)
    fs = rng.choice([2048.0, 10240.0])
    f = rng.uniform(20, 400)
    n = int(rng.uniform(4, 30) * fs / f)
    w, sigma = 2 * np.pi * f, 2 * np.pi * f * rng.uniform(0.003, 0.03)
    r, s = rng.normal() * 0.003 * w * fs / n, rng.normal() * 0.1 * sigma * fs / n
    t, x = _window(n, fs, w, sigma, r, s)
    x = x + rng.normal(0, 0.05, n)
    p, c, misfit = fit_drifts(t, x, w * (1 + rng.normal(0, 1e-3)))
    ref = least_squares(lambda q: _model(q, t) - x, [w, sigma, r, s, 1.3, 0.4], method="lm", xtol=1e-15,
                        ftol=1e-15, gtol=1e-15, x_scale="jac")
    cost = np.sum((_model([*p, c.real, c.imag], t) - x) ** 2)
    assert cost <= 2 * ref.cost * (1 + 1e-10)  # least_squares' cost is half the sum of squares
    *_, se_sigma, se_w = fit_window(t, x, w)  # per unit noise rms
    assert abs(p[0] - ref.x[0]) < 1e-3 * se_w * 0.05 and abs(p[1] - ref.x[1]) < 1e-3 * se_sigma * 0.05


def test_the_decay_rates_standard_error_is_the_scatter_of_repeated_fits():
    """se_sigma times the noise rms against the standard deviation of sigma over 400 noise draws (within 10%)."""
    fs, w, sigma = 2048.0, 2 * np.pi * 60.0, 2 * np.pi * 60.0 * 0.01
    t, x0 = _window(300, fs, w, sigma, 0.0, 0.0)
    rng = np.random.default_rng(3)
    noise = 0.02
    got, se = [], []
    for _ in range(400):
        wi, si, _, _, se_s, _ = fit_window(t, x0 + rng.normal(0, noise, t.size), w, sigma)
        got.append(si)
        se.append(se_s * noise)
    assert abs(np.std(got) / np.mean(se) - 1) < 0.1
    assert abs(np.mean(got) / sigma - 1) < 3 * np.std(got) / sigma / np.sqrt(400)  # unbiased at this noise
