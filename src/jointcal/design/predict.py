"""What a candidate test would measure, for each posterior draw, through the fast steady-state model.

For a draw (Fs, KT, chi, beta, k, zeta_v) and a candidate (base level, sweep direction),
`jointcal.models.steady_state` follows the first-harmonic response along the sweep over
the campaign's band, on the branch a sweep in that direction stays on. The modal stage
reads a base-driven run where the joint's relative motion is in quadrature with the base
(phase resonance): the sweep reaches it where Re Z changes sign between two neighbouring
frequencies of the followed branch (no jump between them). There the work of the base
balances the dissipation, so the read-out amplitude q is the energy-balance root
(`jointcal.models.resonance_amplitude`, exact, not a grid value), and the read-out
frequency and damping are the model's at q, as the calibration compares them
(`jointcal.calibrate.predict`). A sweep that jumps over the quadrature (a fold of a
strongly softening joint past macroslip) gives no phase-resonance read-out. Beside it:
the envelope's peak (response amplitude, g) and the sweep-rate parameter eta =
rate / (f zeta)^2 the modal stage checks (quasi-steady below ``modal.eta_max``).
"""
from __future__ import annotations

from typing import Literal

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..calibrate.objective import predict
from ..calibrate.settings import JOINT
from ..models import resonance_amplitude, steady_state

__all__ = ["READOUT_COLUMNS", "readout"]

READOUT_COLUMNS = ("q_in", "f_hz", "zeta", "reached", "peak_g", "jump", "macroslip")


def _passes_quadrature(Z: NDArray[np.complex128], jump: NDArray[np.bool_], order: NDArray[np.int_]) -> NDArray[np.bool_]:
    """True where Re Z changes sign between neighbouring frequencies of the followed branch (no jump there)."""
    re, js = Z[:, order].real, jump[:, order]
    cross = (np.sign(re[:, :-1]) != np.sign(re[:, 1:])) & ~js[:, 1:] & np.isfinite(re[:, 1:])
    return cross.any(axis=1)


def readout(theta: ArrayLike, level_g: float, direction: Literal["up", "down"], *, m: float, f_lo_hz: float,
            f_hi_hz: float, n_frequencies: int = 400, model: str = "harmonic_balance",
            viscous: str = "dashpot") -> pd.DataFrame:
    """Predicted phase-resonance read-out of one candidate sweep for each draw.

    Parameters
    ----------
    theta : array_like, shape (P, 6)
        Draws of (Fs lbf, KT lbf/in, chi, beta, k lbf/in, zeta_v).
    level_g : float
        Base-acceleration amplitude, g.
    direction : {'up', 'down'}
        Sweep direction.
    m : float
        Slug mass, lbf s^2/in.
    f_lo_hz, f_hi_hz : float
        The sweep's band, Hz.
    n_frequencies : int
        Points of the steady-state sweep over the band.
    model, viscous : str
        As the calibration: the read-out's f and zeta at q.

    Returns
    -------
    pandas.DataFrame
        One row per draw: q_in (in), f_hz, zeta (NaN where the sweep does not pass quadrature),
        reached (bool), peak_g (largest response amplitude along the sweep, g), jump (the
        sweep jumps somewhere), macroslip (q_in beyond phi_max, eq. 3.7).
    """
    th = np.atleast_2d(np.asarray(theta, dtype=float))
    structure = JOINT.model(th, m)
    p = JOINT.named(th)
    f = np.linspace(f_lo_hz, f_hi_hz, n_frequencies)
    ss = steady_state(structure, f, level_g, direction=direction)
    order = np.argsort(f) if direction == "up" else np.argsort(f)[::-1]
    reached = _passes_quadrature(np.atleast_2d(ss.relative), np.atleast_2d(ss.jump), order)
    q, _, _ = resonance_amplitude(level_g, p["Fs"], p["KT"], p["chi"], p["beta"], p["k"], m, p["zeta_v"],
                                  viscous=viscous)  # type: ignore[arg-type]
    q = np.where(reached, q, np.nan)
    with np.errstate(all="ignore"):
        fq, zq = predict(th, np.where(reached, q, 1e-6)[:, None], m=m, model=model,  # type: ignore[arg-type]
                         viscous=viscous)  # type: ignore[arg-type]
    phi_max = JOINT.phi_max(th)
    return pd.DataFrame({"q_in": q, "f_hz": np.where(reached, fq[:, 0], np.nan),
                         "zeta": np.where(reached, zq[:, 0], np.nan), "reached": reached,
                         "peak_g": np.max(np.abs(np.atleast_2d(ss.transmissibility)), axis=1) * level_g,
                         "jump": np.atleast_2d(ss.jump).any(axis=1), "macroslip": reached & (q > phi_max)})
