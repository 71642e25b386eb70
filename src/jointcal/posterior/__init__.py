"""Posterior stage: emcee around the GA optimum, credible intervals and what the data constrain.

Modules: `coords` (sampler coordinates aligned with the identifiable combinations),
`likelihood` (vectorised log-posteriors of any `ParamSpace`: the modal read-outs with
sampled noise scales, and residuals over their scatter), `sampler` (emcee in chunks to
tau_factor x tau, resumable, with an early stop when that is out of reach), `modes` (separated modes
of the draws), `summary` (tables, sentences, predictive band), `fisher` and `identified`
(what the data identify), `settings` (the ``posterior:`` config section) and `stage` (files).
"""
from .coords import Y_NAMES, log_det_dy_dx, x_to_y, y_to_x
from .likelihood import NOISE, LogPosterior, ResidualPosterior
from .modes import find_modes, mode_labels, modes_text
from .sampler import ChainResult, projected_steps, run_chain, sample_ball
from .settings import PosteriorSettings
from .stage import OUTPUTS, goodness_of_fit, run_posterior, start_ball
from .summary import NAMES, burn_in, constraints_text, draw_quantiles, predictive_band, summarize

__all__ = [
    "Y_NAMES", "x_to_y", "y_to_x", "log_det_dy_dx", "NOISE", "LogPosterior", "ResidualPosterior",
    "ChainResult", "run_chain", "sample_ball", "projected_steps",
    "find_modes", "mode_labels", "modes_text", "goodness_of_fit",
    "PosteriorSettings", "OUTPUTS", "run_posterior", "start_ball",
    "NAMES", "burn_in", "summarize", "draw_quantiles", "constraints_text", "predictive_band",
]
