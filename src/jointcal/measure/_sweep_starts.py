"""Start values of the swept-mode fit: linear modes whose modal constant and residual terms are linear least squares.

Private: `jointcal.measure._sweep_problem.fit_from_starts` takes its start values from `starts`.
"""
from __future__ import annotations

import numpy as np

from ._rotating import rotating_mode

__all__ = ["starts", "linear_mode"]


def linear_mode(R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0, f, z, fixed, rot):
    """(misfit norm, A, B_0, B_1, B_2) of a linear mode (f Hz, zeta): its modal constant and residual
    terms by linear least squares (complex; real projections for a fixed phase)."""
    mode = np.array([(2 * np.pi * f) ** 2, 4 * np.pi * f * z, 0, 0, 0, 0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    with np.errstate(all="ignore"):
        x = rotating_mode(R, Rd, Rm, Rdm, W0, h, mode, 1.0, -1.0, 1.0, 0j, 0j)[1][sel]
    if not np.all(np.isfinite(x)):
        return np.inf, 1.0 + 0j, 0j, 0j, 0j
    cols = np.stack([x, R[sel], -1j * Rd[sel] / W0, -Rdd[sel] / W0**2], axis=1)
    y = Acc[sel]
    if fixed:  # real coefficients of (A e^{-i phase}) x, R, -i R'/W0
        cols = cols * np.array([rot, 1.0, 1.0, 1.0])
        c, *_ = np.linalg.lstsq(np.concatenate([cols.real, cols.imag]), np.concatenate([y.real, y.imag]), rcond=None)
        c = c.astype(complex)
        c[0] = c[0] * rot
    else:
        c, *_ = np.linalg.lstsq(cols, y, rcond=None)
    full = np.stack([x, R[sel], -1j * Rd[sel] / W0, -Rdd[sel] / W0**2], axis=1)
    return float(np.linalg.norm(y - full @ c)), *map(complex, c)


def starts(R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0, f0, zeta0, fixed, rot, n_keep=3):
    """Start values (f Hz, zeta, A, B_0, B_1, B_2) of the nonlinear fit, lazily: the caller's (f0, zeta0) first; then,
    only if the fit from it is poor, a scan of linear modes over frequencies within +-5% of f0 (or 4
    half-power widths) and damping ratios from zeta0 / 10 to 10 zeta0 (a chirp faster than the mode, or
    a bent peak, can put an FRF's damping a decade off), the n_keep best distinct ones. A and the
    residual terms start from each linear mode's least squares."""
    args = (R, Rd, Rm, Rdm, Rdd, Acc, sel, h, W0)
    yield f0, zeta0, *linear_mode(*args, f0, zeta0, fixed, rot)[1:]
    df = min(0.05, max(4 * zeta0, 0.002))
    rows = [(*linear_mode(*args, f, z, fixed, rot), f, z)
            for f in f0 * (1 + df * np.linspace(-1, 1, 9)) for z in zeta0 * np.geomspace(0.1, 10.0, 11) if 0 < z < 0.5]
    rows.sort(key=lambda r: r[0])
    kept = [(f0, zeta0)]
    for _, a, b0, b1, b2, f, z in rows:
        if all(abs(f / g - 1) > df / 8 or abs(np.log(z / w)) > 0.3 for g, w in kept):
            kept.append((f, z))
            yield f, z, a, b0, b1, b2
        if len(kept) > n_keep:
            break
