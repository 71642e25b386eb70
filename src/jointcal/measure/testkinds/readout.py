"""The interface every test kind's read-out fills: estimators that return a read-out or refuse with their reason.

A run of a kind that is not swept (`jointcal.io.testkinds`) is first read from its record
(`jointcal.measure.testkinds.read.read_test_run`: the mode's frequency, the decay's start and windows, a
dwell's steady point). Its row of modal_properties.csv is then the first read-out of its kind's rule
(`ReadoutRule`), an ordered tuple of `Estimator`:

* ``estimate(read) -> Readout | Refusal``: a `Readout` is the row's ``f_res_hz``, ``zeta_res``, ``q_in``
  (and the estimator's own columns), its ``flags`` and the backbone points it adds; a `Refusal` says why
  not, in words and in flags;
* ``method``: the word it writes in ``f_res_method`` (the later stages read it: `METHODS`);
* ``clause``: what it reads, in words; ``level_readout``: the modal-table columns where a level's runs of
  it hold one read-out together (a level's dwells: their phase resonance), or None: each run's row is one.

The row's flags are the read's own (``shaker_on``, ``through_force``), each earlier estimator's refusal
flags, then the read-out's; where every estimator refuses, ``unusable``. The rule's words are joined from
its estimators' clauses (`ReadoutRule.text`, quoted by raw_data/README.md).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

from ...io.contract import UNUSABLE

__all__ = ["Readout", "Refusal", "Estimator", "ReadoutRule", "optional"]


@dataclass(frozen=True)
class Readout:
    """A run's read-out: its modal row's columns (``f_res_hz``, ``zeta_res``, ``q_in``, ...), flags and points."""

    columns: Mapping[str, Any]
    flags: tuple[str, ...] = ()
    points: tuple[Mapping[str, Any], ...] = ()  # backbone.csv rows it adds (``q_in``, ``f_hz``, ``zeta``)


@dataclass(frozen=True)
class Refusal:
    """Why an estimator gives no read-out: in words, and as the flags the run's row keeps."""

    reason: str
    flags: tuple[str, ...] = ()


@dataclass(frozen=True)
class Estimator:
    """One way to read a run's (f_res_hz, zeta_res, q_in) (see the module notes)."""

    method: str
    clause: str
    estimate: Callable[[Mapping[str, Any]], "Readout | Refusal"]
    level_readout: tuple[str, str, str] | None = None


def optional(estimator: Estimator, what: str) -> Estimator:
    """`estimator` for a part of a record that may be absent (`what`, in words): its refusals flag nothing."""
    def estimate(read):
        out = estimator.estimate(read)
        return Refusal(out.reason) if isinstance(out, Refusal) else out
    return replace(estimator, clause=f"where {what}, {estimator.clause}", estimate=estimate)


@dataclass(frozen=True)
class ReadoutRule:
    """A test kind's read-out rule: its name (`jointcal.io.testkinds`) and its estimators, tried in order."""

    test: str
    estimators: tuple[Estimator, ...]

    @property
    def text(self) -> str:
        """The rule in words, joined from its estimators' clauses."""
        steps = " ".join(f"({i}) {e.clause};" for i, e in enumerate(self.estimators, 1))
        return f"A {self.test} run is read by the first of: {steps} else it is unusable."

    def read(self, read: Mapping[str, Any]) -> tuple[Estimator | None, dict[str, Any], list[str], list]:
        """The first estimator's read-out: (estimator or None, its columns, the row's flags, its points)."""
        flags = list(read["flags"])
        for est in self.estimators:
            out = est.estimate(read)
            if isinstance(out, Readout):
                cols = dict(out.columns)
                head = {k: cols.pop(k) for k in ("f_res_hz", "zeta_res", "q_in")}
                return est, {**head, "f_res_method": est.method, **cols}, flags + list(out.flags), list(out.points)
            flags += out.flags
        return None, {}, flags + [UNUSABLE], []
