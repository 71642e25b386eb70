"""The posterior stage of one (assembly, mode) as the workflow runs it: the chain, then what it identifies.

`run_posterior_unit` is `jointcal.posterior.stage.run_posterior` (summary.csv, chain.npz, constraints.txt,
predictive.csv, with the chain's checkpoint) followed by
`jointcal.posterior.identified.write_identified` (identified.csv, from the draws just written), from the
config's sections. Kept apart from `jointcal.posterior.stage`, which other stages import, so that their
code hashes (`jointcal._workflow.stage_hash`) do not hold `identified`.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from ..calibrate.settings import CalibrateSettings
from .identified import write_identified
from .settings import PosteriorSettings
from .stage import run_posterior

__all__ = ["run_posterior_unit"]

_Path = str | os.PathLike[str]


def run_posterior_unit(modal_csv: _Path, scatter_csv: _Path, backbone_csv: _Path, ga_best_json: _Path,
                       assembly: str, *, summary_csv: _Path, chain_npz: _Path, identified_csv: _Path,
                       calibrate: Mapping[str, Any], posterior: Mapping[str, Any], checkpoint: _Path | None = None,
                       log: Callable[[str], None] = lambda line: None,
                       warn: Callable[[str], None] = lambda line: None) -> list[str]:
    """Sample one unit's posterior, write the stage's outputs, then ``identified.csv``.

    Parameters
    ----------
    modal_csv, scatter_csv, backbone_csv : path
        The unit's modal tables (`jointcal.measure.stage.run_modal_unit`).
    ga_best_json : path
        The calibration's optimum, where the walkers start.
    assembly : str
    summary_csv : path
        Where ``summary.csv`` goes; ``constraints.txt`` and ``predictive.csv`` go beside it.
    chain_npz : path
        The ``chain.npz`` written beside ``summary.csv``, which ``identified.csv`` is read from.
    identified_csv : path
        Where ``identified.csv`` goes.
    calibrate, posterior : mapping
        The config's sections.
    checkpoint : path, optional
        The chain's checkpoint: resumed from when it matches.
    log : callable, optional
        Receives the chain's progress and the notes.
    warn : callable, optional
        Receives the notes that are warnings: a floor applied to a noise scale, a chain not converged.

    Returns
    -------
    list of str
        The notes, in the order they were logged.
    """
    cal = CalibrateSettings.from_config(calibrate)
    post = PosteriorSettings.from_config(posterior)
    _, notes = run_posterior(modal_csv, scatter_csv, ga_best_json, assembly, Path(summary_csv).parent, cal, post,
                             checkpoint=checkpoint, progress=log, backbone_csv=backbone_csv)
    notes.append(write_identified(modal_csv, ga_best_json, chain_npz, assembly, cal, post, identified_csv,
                                  backbone_csv=backbone_csv))
    for n in notes:
        (warn if "floor" in n or "NOT converged" in n else log)(n)
    return notes
