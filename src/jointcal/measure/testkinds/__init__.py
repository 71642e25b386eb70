"""Test kinds' read-outs: each kind that is not swept reads its runs by its own rule, one module each, one registry.

The test kinds' contract rows (manifest columns, checks, reader) are `jointcal.io.testkinds`, the
bottom layer; their read-outs need this layer's estimators, so they register here under the same
names (`registry.READOUT_RULES`). A rule is an ordered tuple of estimators (`readout.Estimator`),
each returning a `readout.Readout` or a `readout.Refusal` with its reason; the run's row of
modal_properties.csv is the first read-out, its flags the refusals before it, and the rule's words
are joined from the estimators' own clauses (`rule_text`: raw_data/README.md quotes them, a test
checks it). A sweep is read by `jointcal.measure.modal.READOUT_RULE` (`jointcal.measure.campaign`).

=========  ====================================================================================
kind       read-out rule (estimators, in order; ``f_res_method``)
=========  ====================================================================================
dwell      its steady point with its level's modal constant (``dwell``); else, where the record
           goes on after the cut, its ring-down's largest-amplitude window (``ringdown``)
ringdown   its ring-down's largest-amplitude window (``ringdown``)
=========  ====================================================================================

Modules: `read` (a run read from its record: the mode's frequency, the decay's windows, a dwell's
point; a level's dwells' modal constant; the modal rows and backbone.csv), `readout` (the
interface), `registry`, and one module per kind (`dwell`, `ringdown`). This ``__init__`` imports
the rules, not `read` (import from it), so that the stages above that only ask a read-out's
``f_res_method`` (calibrate) hash the rules alone (`jointcal._workflow.stage_hash`).

How to add a kind's read-out: write ``jointcal/measure/testkinds/<name>.py`` holding ``RULE =
ReadoutRule(name, (estimator, ...))``, each estimator ``Estimator(method, clause, estimate)``;
import it and ``register`` it below; quote `rule_text` in raw_data/README.md's *Test kinds*.
"""
from . import dwell, ringdown
from .readout import Estimator, Readout, ReadoutRule, Refusal, optional
from .registry import READOUT_RULES, estimator_of, level_readout, methods, register

for _module in (dwell, ringdown):
    register(_module.RULE)


def rule_text() -> str:
    """Every registered kind's read-out rule in words, one sentence per kind (raw_data/README.md quotes it)."""
    return " ".join(r.text for r in READOUT_RULES.values())


__all__ = ["READOUT_RULES", "register", "methods", "estimator_of", "level_readout", "rule_text", "Estimator", "Readout", "Refusal",
           "ReadoutRule", "optional"]
