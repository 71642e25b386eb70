"""The calibrated model as a `MinistackModel`: from the GA optimum and from posterior draws.

Viscous convention (see `jointcal.models.amplitude`): a calibration with ``viscous:
dashpot`` fitted exactly the dashpot of `MinistackModel` (zeta_v is its ratio at the
stuck-joint frequency omega_0), so zeta_v is taken as it is. With ``viscous: constant``
zeta_v is a ratio added at every frequency (the paper's convention), which no linear
dashpot reproduces; it is converted to the dashpot that has that ratio at a reference
frequency f_ref (the measured resonance): zeta_dashpot = zeta_v f_ref / f_0, since a
dashpot's ratio at omega is zeta_dashpot omega_0 / omega.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..calibrate.space import PARAMS as _KEYS
from ..models import IwanParams, MinistackModel

__all__ = ["model_from_params", "model_from_best", "models_from_samples", "run_models"]


def model_from_params(params: Mapping[str, float], m: float, *, viscous: str = "dashpot",
                      f_ref_hz: float | None = None) -> MinistackModel:
    """A `MinistackModel` from (Fs lbf, KT lbf/in, chi, beta, k lbf/in, zeta_v) and the slug mass m (lbf s^2/in).

    Parameters
    ----------
    params : mapping
        The six calibrated parameters by name.
    m : float
        Slug mass, lbf s^2/in.
    viscous : {'dashpot', 'constant'}
        Convention zeta_v was calibrated with (module docstring).
    f_ref_hz : float, optional
        Reference frequency (Hz) of the 'constant' conversion; required then.
    """
    missing = [k for k in _KEYS if k not in params]
    if missing:
        raise ValueError(f"calibrated parameters lack {', '.join(missing)}; rerun the calibrate stage.")
    p = {k: float(params[k]) for k in _KEYS}
    zeta_v = p["zeta_v"]
    if viscous == "constant":
        if f_ref_hz is None or not f_ref_hz > 0:
            raise ValueError("a model calibrated with viscous 'constant' needs a reference frequency f_ref_hz > 0 "
                             "(the measured resonance) to become a dashpot.")
        f0 = np.sqrt((p["k"] + p["KT"]) / m) / (2 * np.pi)  # the stuck joint's frequency
        zeta_v = zeta_v * f_ref_hz / f0
    elif viscous != "dashpot":
        raise ValueError(f"viscous must be 'dashpot' or 'constant', got {viscous!r}.")
    return MinistackModel(m=float(m), k=p["k"], zeta_v=zeta_v, iwan=IwanParams(p["Fs"], p["KT"], p["chi"], p["beta"]))


def model_from_best(best: Mapping[str, Any], *, f_ref_hz: float | None = None) -> MinistackModel:
    """The model of a calibration's ``ga_best.json`` (keys Fs, KT, chi, beta, k, zeta_v, m, viscous).

    f_ref_hz is needed only for ``viscous: constant`` (see `model_from_params`).
    """
    if "m" not in best:
        raise ValueError("ga_best.json lacks the slug mass 'm'; rerun the calibrate stage.")
    return model_from_params(best, float(best["m"]), viscous=str(best.get("viscous", "dashpot")), f_ref_hz=f_ref_hz)


def models_from_samples(samples: ArrayLike, m: float, n_draws: int, rng: np.random.Generator, *,
                        viscous: str = "dashpot", f_ref_hz: float | None = None,
                        names: Sequence[str] = _KEYS) -> list[MinistackModel]:
    """`n_draws` models drawn without replacement from posterior samples.

    Parameters
    ----------
    samples : array_like, shape (S, >= 6)
        Posterior draws in physical units (``chain.npz`` key ``samples``), columns named by
        `names`: the joint's six (Fs, KT, chi, beta, k, zeta_v) among them.
    m : float
        Slug mass, lbf s^2/in.
    n_draws : int
        Models wanted (all samples if fewer).
    rng : numpy.random.Generator
        Picks the draws.
    names : sequence of str
        Names of the leading columns of `samples` (``chain.npz`` key ``sample_names``);
        default the joint's six.
    """
    s = np.asarray(samples, dtype=float)
    names = [str(p) for p in names]
    if s.ndim != 2 or s.shape[1] < len(names) or not set(_KEYS) <= set(names):
        raise ValueError(f"posterior samples must have shape (draws, >= {len(names)}) with columns "
                         f"{', '.join(_KEYS)} among {', '.join(names)}, got shape {s.shape}.")
    s = s[:, [names.index(p) for p in _KEYS]]
    s = s[np.all(np.isfinite(s), axis=1)]
    pick = rng.choice(len(s), size=min(int(n_draws), len(s)), replace=False) if len(s) else []
    return [model_from_params(dict(zip(_KEYS, s[i])), m, viscous=viscous, f_ref_hz=f_ref_hz)
            for i in np.sort(pick)]


def run_models(best: Mapping[str, Any], f_res_hz: Mapping[str, float],
               run_ids: list[str]) -> tuple[list[MinistackModel], float | None]:
    """The optimum's model for each run, and the reference frequency its posterior draws use.

    f_ref (needed only for ``viscous: constant``, see `model_from_params`) is each run's own
    measured resonance, or, for a run without one, the median over the runs that have one;
    the draws, shared by every run, take that median.

    Parameters
    ----------
    best : mapping
        ga_best.json's content.
    f_res_hz : mapping of str to float
        Measured resonance per run_id (modal_properties.csv's ``f_res_hz``, Hz; NaN or absent
        where a run has none).
    run_ids : list of str
        The runs, in the order of the models returned.

    Returns
    -------
    models : list of MinistackModel
        One per run of `run_ids`.
    f_ref_hz : float or None
        The median resonance (Hz), None when no run has one.
    """
    f = {r: float(f_res_hz[r]) for r in run_ids if r in f_res_hz}
    f_ref = float(np.nanmedian(list(f.values()))) if f else None
    models = [model_from_best(best, f_ref_hz=f[r] if np.isfinite(f.get(r, np.nan)) else f_ref) for r in run_ids]
    return models, f_ref
