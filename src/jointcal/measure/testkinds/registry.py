"""The registry of the test kinds' read-out rules: register, look up by the kind's name, the methods they write."""
from __future__ import annotations

from .readout import Estimator, ReadoutRule

__all__ = ["READOUT_RULES", "register", "methods", "estimator_of", "level_readout"]

READOUT_RULES: dict[str, ReadoutRule] = {}  # test kind (`jointcal.io.testkinds`) -> its read-out rule


def register(rule: ReadoutRule) -> ReadoutRule:
    """Add a test kind's read-out rule (the modal stage then reads its runs by it)."""
    READOUT_RULES[rule.test] = rule
    return rule


def methods() -> tuple[str, ...]:
    """Every ``f_res_method`` the registered rules write (a row read by none of them is a sweep's)."""
    return tuple(dict.fromkeys(e.method for r in READOUT_RULES.values() for e in r.estimators))


def estimator_of(method: object) -> Estimator | None:
    """The estimator that writes ``f_res_method`` `method`, or None (a sweep's read-out)."""
    return next((e for r in READOUT_RULES.values() for e in r.estimators if e.method == method), None)


def level_readout(test: str) -> tuple[str, str, str] | None:
    """The modal-table columns (q, f, zeta) where a level's runs of kind `test` hold one read-out together (a
    level's dwells: their phase resonance), or None where each run's row is its own."""
    rule = READOUT_RULES.get(test)
    return next((e.level_readout for e in rule.estimators if e.level_readout), None) if rule else None
