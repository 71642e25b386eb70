"""Design stage: which test to run next, predicted from the posterior through the fast steady-state model.

Modules in the order data flows: `settings` (the ``design:`` config section),
`candidates` (tests the user can run: levels up to the shaker limit, directions, sweep
rates, and their duration), `predict` (each candidate's phase-resonance read-out for each
posterior draw), `narrowing` (the criterion: predicted narrowing of every quantity's 90%
interval and the expected information gain, local Laplace at each draw taken as the
truth), `evaluate` (every candidate), `recommend` (ranking, the recommendation and its
words) and `stage` (files).
"""
from .candidates import campaign_sweep, candidates, level_series
from .evaluate import REPORTED, evaluate
from .narrowing import CRITERION, narrowing
from .predict import readout
from .recommend import RULE, next_test_markdown, rank, recommendation
from .settings import DesignSettings
from .stage import OUTPUTS, run_design, targets_of, words_now

__all__ = [
    "DesignSettings", "candidates", "campaign_sweep", "level_series", "readout", "CRITERION", "narrowing",
    "REPORTED", "evaluate", "RULE", "rank", "recommendation", "next_test_markdown",
    "OUTPUTS", "run_design", "targets_of", "words_now",
]
