"""The discrepancy workflow (issue 9): where simulation and measurement disagree, which named
physical effect is missing, the model with it added, and the gap before and after.

Modules in the order data flows: `library` (the named effects), `data` (measured envelope
frames), `fit` (the fast-model envelope objective and its fits), `fingerprints` (residual
maps, fingerprint features), `select` (held-out scoring and the decision rule), `stage`
(one assembly, end to end).
"""
from .library import EFFECTS, Effect, EffectParam, apply_effect
from .select import decide, score_candidates
from .stage import DiscrepancySettings, diagnose, diagnosis_markdown

__all__ = ["EFFECTS", "Effect", "EffectParam", "apply_effect", "decide", "score_candidates",
           "DiscrepancySettings", "diagnose", "diagnosis_markdown"]
