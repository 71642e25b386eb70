"""What a force-referenced campaign measured of a mode at the driving point: its modal constant and the other
modes' residual receptance, to read its decays through the force (`jointcal.measure.forced_decay`).

A decay that the shaker still pushes on is read through A / (H - R) (`forced_decay.structure_pole`). A is the
swept-mode fit's modal constant (`jointcal.measure.sweepfit`: 1/m for a force at the driving point, fitted with
the mode's amplitude dependence). R is the other modes' flexibility at the driving point near the mode: on a
1 lbf, 100 Hz beam with a second mode at 230 Hz (0.5 lbf) it is 1.5% of the mode's receptance at resonance but
moves the decay's read-out by -0.05% in f and +1% in zeta, where the rig's pole lies 2.4% off the structure's.
A single-mode fit of the whole FRF peak (`jointcal.measure.modefit`) puts R wrong in size and sign on a jointed
beam (the bent peak's distortion goes into it); the peak's flanks, where the joint barely slips, hold it
(`flank_receptance`: within 3.5% on that beam's lowest-level sweep).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

__all__ = ["Receptance", "flank_receptance", "FLANK"]

FLANK = 0.15  # FRF lines below this share of the peak's |X|: the mode's flanks, its joint barely slipping


@dataclass(frozen=True)
class Receptance:
    """What a campaign measured of one mode at the driving point, to read its decays through the force.

    modal_constant : complex, (in/s^2) per lbf (1/m), e.g. a force-referenced sweep fit's.
    r0 : float, in/lbf, and r2 : float, in/lbf per (rad/s)^2: the other modes' receptance near the mode,
        R(w) = r0 + r2 w^2 (a stiffness line and its first mass correction).
    source : str, the run(s) it was measured on.
    """

    modal_constant: complex
    r0: float = 0.0
    r2: float = 0.0
    source: str = ""

    def residual(self, f_hz: float) -> float:
        """R at f_hz (Hz), in/lbf."""
        return float(self.r0 + self.r2 * (2 * np.pi * f_hz) ** 2)


def flank_receptance(f_hz: ArrayLike, X: ArrayLike, modal_constant: complex, *, flank: float = FLANK,
                     source: str = "") -> Receptance:
    """The other modes' receptance near a mode, from a force-referenced FRF's flanks, its modal constant known.

    On the lines where |X| is below `flank` of its peak (both sides of the mode, the joint at a small share
    of its peak amplitude: nearly linear) the FRF is fitted by
    ``X = A / (W - w^2 + i w C) + r0 + r2 w^2`` with A given and W, C (the mode there) and r0, r2 (real) fitted:
    W and C by least squares, r0 and r2 by variable projection. At the peak a bent, amplitude-dependent mode
    would take the residual terms into its own distortion (a single-mode fit of the whole peak of a jointed
    beam put them wrong in size and sign); on its flanks the mode is nearly the linear one and the known A
    fixes its size.

    Parameters
    ----------
    f_hz : array_like, shape (k,)
        FRF lines, Hz (a sweep's band; its edges, where the drive ramps, left out by the caller).
    X : array_like of complex, shape (k,)
        Displacement over force on those lines, in/lbf (`jointcal.measure.frf.displacement_ratio`).
    modal_constant : complex
        A, (in/s^2) per lbf.
    flank : float
        Lines below this share of the largest |X| are fitted.
    source : str
        Kept in the result.

    Returns
    -------
    Receptance
    """
    f = np.asarray(f_hz, float)
    X = np.asarray(X, complex)
    A = complex(modal_constant)
    ok = np.isfinite(f) & np.isfinite(X) & (f > 0)
    f, X = f[ok], X[ok]
    if f.size < 8 or not (np.isfinite(A) and A != 0):
        raise ValueError(f"the receptance needs 8 finite FRF lines and a finite, nonzero modal constant; got "
                         f"{f.size} lines and A = {modal_constant!r}.")
    ip = int(np.argmax(np.abs(X)))
    use = np.abs(X) < flank * np.abs(X[ip])
    if not (use[:ip].sum() >= 4 and use[ip:].sum() >= 4):
        raise ValueError(f"the FRF has fewer than 4 lines below {flank:g} of its peak on each side of it "
                         f"({f.min():g}-{f.max():g} Hz, peak at {f[ip]:g} Hz); sweep further past the mode.")
    w, Xu = 2 * np.pi * f[use], X[use]
    B = np.vstack([np.stack([np.ones_like(w), w**2], 1), np.zeros((w.size, 2))])
    scale = float(np.abs(Xu).max())
    w_pk = 2 * np.pi * f[ip]

    def fit(p):
        M = Xu - A / (p[0] * w_pk**2 - w**2 + 1j * w * p[1] * w_pk)
        y = np.concatenate([M.real, M.imag])
        c = np.linalg.lstsq(B, y, rcond=None)[0]
        return c, (y - B @ c) / scale

    half = 0.5 * abs(A) / (w_pk**2 * scale)  # the peak's half-width from its height: |X| ~ A / (w^2 2 zeta)
    p = least_squares(lambda p: fit(p)[1], [1.0, max(2 * half, 1e-4)], x_scale=[1e-3, 1e-3]).x
    r0, r2 = fit(p)[0]
    return Receptance(A, float(r0), float(r2), source)
