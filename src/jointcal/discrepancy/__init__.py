"""The discrepancy workflow: where simulation and measurement disagree, which named physical
effect (or pair of effects) is missing, the model with it added, and the gap before and after.

The effects it tries are the library of `jointcal.effects` (one module each). Modules in
the order data flows: `data` (measured envelope
frames and the run's drive), `fit` (the swept fast-model envelope objective and its fits),
`floor` (the fast model's own error against the time simulation), `fingerprints`
(residual maps, fingerprint features), `select` (held-out scoring, forward selection), `rule`
(the decision rule), `recalibrate` (GA, polish, posterior of the chosen model), `stage`
(one assembly, end to end), `words` (the diagnosis in plain language). A campaign of ring-downs and
dwells: `decays` (their backbone points and the objective on them) and `decay_stage` (its steps).

The effects themselves are imported from `jointcal.effects` (one import path).
"""
from .rule import decide
from .select import score_candidates
from .stage import DiscrepancySettings, diagnose
from .words import diagnosis_markdown

__all__ = ["decide", "score_candidates",
           "DiscrepancySettings", "diagnose", "diagnosis_markdown"]
