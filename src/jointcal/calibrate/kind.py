"""What the calibrated model is: the paper's Ministack, or one mode of any structure.

Both kinds are the same equation, a mass m on a linear spring k in parallel with the
four-parameter Iwan joint (Fs, KT, chi, beta; eqs. 3.1-3.7) and a viscous dashpot zeta_v,
and the same amplitude-dependent frequency and damping (`jointcal.models.harmonic_balance`).
They differ in what m is, where the amplitude q is taken, and the bounds the data call for:

* ``ministack`` (base-driven campaigns, the paper's test): m is the slug (its weight
  ``slug_weight_lbf`` / 386.089, lbf s^2/in), q the joint's relative displacement, and
  the bounds are `DEFAULT_BOUNDS` (stuck frequencies 190 Hz to 19 kHz with the 2.65 lbf
  slug), or the config's.
* ``modal`` (force- and voltage-driven campaigns): one mode of any structure, its
  amplitude q the mode's displacement at the response sensor. m is the modal mass at that
  point (``modal_mass``, lbf s^2/in) when known; otherwise 1, and the results are per
  unit modal mass: the parameters of a mode of modal mass 1 lbf s^2/in (multiply Fs, KT and
  k by the true modal mass; chi, beta and zeta_v do not change). The bounds come from the
  data (`data_bounds`), not from the Ministack's numbers. For a voltage reference the mode
  is the rig's: the shaker's armature mass, suspension and back-EMF damping are in it.

``auto`` takes the kind from the modal table's level column (level_g: base; level_lbf,
level_V: force, voltage).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Literal

import numpy as np
import pandas as pd

from ..io.contract import LEVEL, excitation_kind
from ..models import harmonic_balance

__all__ = ["KINDS", "Kind", "excitation_of_table", "kind_of", "data_bounds", "model_words", "backbone_at"]

Kind = Literal["ministack", "modal"]
KINDS: tuple[str, ...] = ("auto", "ministack", "modal")


def excitation_of_table(modal: pd.DataFrame) -> str:
    """The campaign's excitation, 'base', 'force' or 'voltage', from the modal table's level column."""
    cols = [col for col in LEVEL.values() if col in modal.columns]
    if len(cols) != 1:
        raise ValueError("the modal table needs exactly one level column (level_g, level_lbf or level_V), "
                         f"got {', '.join(c for c in modal.columns if str(c).startswith('level')) or 'none'}; "
                         "rerun the modal stage.")
    return excitation_kind(cols)


def kind_of(requested: str, excitation: str) -> Kind:
    """The model kind: `requested` unless 'auto', which follows the excitation (base: ministack)."""
    if requested not in KINDS:
        raise ValueError(f"calibrate.model_kind must be one of {', '.join(KINDS)}, got {requested!r}")
    if requested != "auto":
        return requested  # type: ignore[return-value]
    return "ministack" if excitation == "base" else "modal"


def data_bounds(q: np.ndarray, f: np.ndarray, zeta: np.ndarray, m: float) -> dict[str, list[float]]:
    """Search bounds of a single mode from its own measurements.

    Parameters
    ----------
    q, f, zeta : ndarray, shape (N,)
        Amplitude (in), resonance (Hz) and damping ratio of the usable runs.
    m : float
        Modal mass, lbf s^2/in (1 per unit modal mass).

    Returns
    -------
    dict
        {name: [lower, upper]}. K0 = m (2 pi f)^2 at the smallest amplitude is about the
        stuck stiffness k + KT (a softening joint: the lowest level is the stiffest), so k
        and KT each lie within [1e-3, 2] K0. The slip force Fs sets where macroslip starts
        (phi_max ~ Fs / KT): from 1e-2 K0 q_min (macroslip below the smallest amplitude) to
        1e3 K0 q_max (the joint barely slips over the measured range). zeta_v up to twice the
        largest measured damping (at least 0.1); chi and beta as for any joint.
    """
    q, f, zeta = (np.asarray(a, float) for a in (q, f, zeta))
    k0 = m * (2 * np.pi * float(f[np.argmin(q)])) ** 2
    return {"Fs": [1e-2 * k0 * float(q.min()), 1e3 * k0 * float(q.max())],
            "KT": [1e-3 * k0, 2.0 * k0], "chi": [-0.95, 0.0], "beta": [1.0e-4, 5.0],
            "k": [1e-3 * k0, 2.0 * k0], "zeta_v": [1.0e-4, max(0.1, 2.0 * float(np.nanmax(zeta)))]}


def model_words(best: Mapping) -> str:
    """What the parameters mean, in one paragraph, from a calibration's ga_best.json."""
    kind, exc = best.get("model_kind", "ministack"), best.get("excitation", "base")
    if kind == "ministack":
        return (f"The paper's Ministack model: a slug of mass {best.get('m', float('nan')):.4g} lbf s^2/in on the "
                "spring k in parallel with the Iwan joint (Fs, KT, chi, beta) and a dashpot (zeta_v); q is the "
                "joint's relative displacement amplitude.")
    mass = ("per unit modal mass: the parameters of a mode of modal mass 1 lbf s^2/in at the response sensor "
            "(multiply Fs, KT and k by the true modal mass; chi, beta and zeta_v do not change)"
            if best.get("per_unit_modal_mass", True)
            else f"with the given modal mass {best.get('m', float('nan')):.4g} lbf s^2/in")
    rig = (" The reference is the amplifier's voltage, so the mode is the rig's: the shaker's armature mass, "
           "suspension and back-EMF damping are in k, zeta_v and the frequencies." if exc == "voltage" else
           " The reference is the force at the driving point: the mode is the structure's own.")
    return (f"One mode of the structure ({exc}-driven): a modal mass on the spring k in parallel with the Iwan "
            f"joint (Fs, KT, chi, beta) and a dashpot (zeta_v), {mass}; q is the mode's displacement amplitude "
            f"at the response sensor, the largest the run reached.{rig} The bounds came from the data.")


def backbone_at(joint: Mapping[str, float], m: float, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frequency (Hz) and damping ratio of either kind at amplitudes q (in): the harmonic balance of the mass m
    on k, the Iwan joint (Fs, KT, chi, beta) and the dashpot zeta_v (eqs. 3.1-3.7; `models.harmonic_balance`)."""
    f, z = harmonic_balance(np.asarray(q, float), joint["Fs"], joint["KT"], joint["chi"], joint["beta"], joint["k"],
                            m, joint["zeta_v"])
    return np.asarray(f, float), np.asarray(z, float)
