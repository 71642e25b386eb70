"""The corner plot's axes: log10 of the scale parameters and noise scales, chi linear."""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..calibrate.space import LOG_SCALED

__all__ = ["corner_coordinates"]


def corner_coordinates(samples: NDArray[np.float64], names: Sequence[str], points: Mapping[str, Mapping[str, float]],
                       bounds: Mapping[str, Sequence[float]]) -> tuple[NDArray[np.float64], list[str],
                                                                       dict[str, list[float]],
                                                                       tuple[list[float], list[float]]]:
    """Posterior draws, marked points and prior bounds in the corner plot's coordinates.

    A name `jointcal.calibrate.LOG_SCALED` marks linear (chi) stays linear; every other name
    (the scale parameters, and the noise scales it does not list) is shown as log10.

    Parameters
    ----------
    samples : ndarray, shape (S, D)
        Draws in physical units (lbf, lbf/in, dimensionless), columns named by `names`.
    names : sequence of str, length D
        The draws' columns (chain.npz's ``sample_names``).
    points : mapping label -> mapping name -> float
        Points to mark (e.g. "GA best", "polished optimum"), physical units; a name a point
        lacks is NaN (not drawn).
    bounds : mapping name -> (low, high)
        Prior bounds, physical units; names without bounds are NaN.

    Returns
    -------
    x : ndarray, shape (S, D)
        The draws on the plot's axes.
    labels : list of str
        ``"log10 <name>"`` or ``"<name>"``.
    marks : dict label -> list of float (D,)
        The points on the plot's axes.
    limits : (list of float, list of float)
        Lower and upper bounds on the plot's axes.
    """
    log = [LOG_SCALED.get(n, True) for n in names]
    x = np.where(log, np.log10(np.abs(samples)), samples)
    labels = [f"log10 {n}" if lg else n for n, lg in zip(names, log)]

    def on_axes(point: Mapping[str, float]) -> list[float]:
        return [(np.log10(point[n]) if lg else point[n]) if n in point else np.nan for n, lg in zip(names, log)]

    lo = [bounds[n][0] if n in bounds else np.nan for n in names]
    hi = [bounds[n][1] if n in bounds else np.nan for n in names]
    marks = {label: on_axes(p) for label, p in points.items()}
    return x, labels, marks, (on_axes(dict(zip(names, lo))), on_axes(dict(zip(names, hi))))
