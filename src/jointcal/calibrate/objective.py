"""The GA objective, eq. 3.9, for a whole population in one vectorised model call.

Gamma(p) = eta/N sum_i ((f_i - f~(q_i, p))/f_i)^2
         + (1 - eta)/N sum_i ((zeta_i - zeta~(q_i, p))/zeta_i)^2

on the measured resonance amplitude q_i (in), frequency f_i (Hz) and damping ratio
zeta_i of each usable run. Where a run gives many points (a ring-down's windows), each
squared residual carries the point's weight w_i and N = sum w_i, the number of read-outs
(`jointcal.calibrate._readouts`); with one point per run every w_i is 1.

The model is `harmonic_balance` (default: the frequency a steady sweep shows at phase
resonance) or `qsma` (the paper's quasi-static modal analysis, 0.15-0.35% stiffer). The viscous term follows the convention named by
``viscous`` (see `jointcal.models.amplitude`): ``"dashpot"`` (default for both models,
so zeta_v means the same physical dashpot whichever model is fitted, and matches what
a time simulation or a test with a linear dashpot shows) or ``"constant"`` (the paper's
zeta_viscous added as a constant).
"""
from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..models import harmonic_balance, population_curves, qsma
from .space import PARAMS

__all__ = ["PENALTY", "Model", "MODELS", "predict", "objective"]

Model = Literal["harmonic_balance", "qsma"]
MODELS: dict[str, object] = {"harmonic_balance": harmonic_balance, "qsma": qsma}
PENALTY = 1.0e10  # objective of an invalid parameter set: large and finite, never NaN


def predict(theta: ArrayLike, q: ArrayLike, *, m: float, model: Model = "harmonic_balance",
            viscous: Literal["dashpot", "constant"] = "dashpot"
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Model frequency and damping of many parameter sets at many amplitudes.

    Parameters
    ----------
    theta : array_like, shape (P, 6)
        Physical parameters (Fs lbf, KT lbf/in, chi, beta, k lbf/in, zeta_v) per row.
    q : array_like, shape (N,)
        Relative displacement amplitudes, in (> 0).
    m : float
        Slug mass, lbf s^2/in.
    model : {'harmonic_balance', 'qsma'}
        Amplitude-dependent model.
    viscous : {'dashpot', 'constant'}
        Viscous-damping convention.

    Returns
    -------
    f : ndarray, shape (P, N)
        Natural frequency, Hz.
    zeta : ndarray, shape (P, N)
        Damping ratio (0.02, not 2%).
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    if theta.shape[-1] != len(PARAMS):
        raise ValueError(f"theta must have {len(PARAMS)} columns ({', '.join(PARAMS)}), got shape {theta.shape}")
    q = np.asarray(q, dtype=float)
    if q.ndim == 1 and theta.ndim == 2 and np.ndim(m) == 0:  # a population at the same amplitudes: one kernel call
        return population_curves(theta, q, m, harmonic=model == "harmonic_balance", viscous=viscous)
    v = dict(zip(PARAMS, np.split(theta, len(PARAMS), axis=1)))  # the joint's columns by name, (P, 1) each
    fn = MODELS[model]
    return fn(q, v["Fs"], v["KT"], v["chi"], v["beta"], v["k"], m,  # type: ignore[operator]
              v["zeta_v"], viscous=viscous)


def objective(theta: ArrayLike, q: ArrayLike, f: ArrayLike, zeta: ArrayLike, *, m: float, eta: float = 0.85,
              model: Model = "harmonic_balance", viscous: Literal["dashpot", "constant"] = "dashpot",
              valid: ArrayLike | None = None, weight: ArrayLike | None = None) -> NDArray[np.float64]:
    """Eq. 3.9 for each row of `theta`.

    Parameters
    ----------
    theta : array_like, shape (P, 6)
        Physical parameters per individual (see `predict`).
    q, f, zeta : array_like, shape (N,)
        Measured amplitude (in), frequency (Hz) and damping ratio per usable run.
    m : float
        Slug mass, lbf s^2/in.
    eta : float
        Weight of the frequency residuals, in [0, 1] (0.85 as the paper).
    model, viscous : str
        See `predict`.
    valid : array_like of bool, shape (P,), optional
        Rows to evaluate (e.g. those inside the bounds); the others get `PENALTY`.
    weight : array_like, shape (N,), optional
        Each point's weight (`jointcal.calibrate.ModalData.w`); default 1 each.

    Returns
    -------
    ndarray, shape (P,)
        Gamma per individual (dimensionless); `PENALTY` where the row is invalid or the
        model is not finite.
    """
    if not 0.0 <= eta <= 1.0:
        raise ValueError(f"eta must lie in [0, 1], got {eta!r}")
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    f, zeta = np.asarray(f, dtype=float), np.asarray(zeta, dtype=float)
    ok = np.all(np.isfinite(theta), axis=1)
    if valid is not None:
        ok &= np.asarray(valid, dtype=bool)
    out = np.full(theta.shape[0], PENALTY)
    if not ok.any():
        return out
    with np.errstate(all="ignore"):
        f_m, z_m = predict(theta[ok], q, m=m, model=model, viscous=viscous)
        if weight is None:
            n = f.size
            gamma = (eta / n) * np.sum(((f - f_m) / f) ** 2, axis=1)  # eq. 3.9, frequency term
            gamma += ((1.0 - eta) / n) * np.sum(((zeta - z_m) / zeta) ** 2, axis=1)  # eq. 3.9, damping term
        else:  # eq. 3.9 over read-outs: each point's squared residual times its weight, N = sum of the weights
            w = np.asarray(weight, dtype=float)
            n = float(np.sum(w))
            gamma = (eta / n) * np.sum(w * ((f - f_m) / f) ** 2, axis=1)
            gamma += ((1.0 - eta) / n) * np.sum(w * ((zeta - z_m) / zeta) ** 2, axis=1)
    out[ok] = np.where(np.isfinite(gamma), np.minimum(gamma, PENALTY), PENALTY)
    return out
