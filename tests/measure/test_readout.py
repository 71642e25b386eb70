"""The test kinds' read-out rules (jointcal.measure.testkinds): estimators tried in order, each a read-out or a
refusal with its reason; the rule's words, joined from their clauses, are the ones raw_data/README.md states."""
from __future__ import annotations

from pathlib import Path

from jointcal.io.testkinds import TEST_KINDS
from jointcal.measure.testkinds import (READOUT_RULES, Estimator, Readout, ReadoutRule, Refusal, estimator_of,
                                        level_readout, methods, optional, rule_text)

REPO = Path(__file__).resolve().parents[2]


def test_raw_data_readme_states_the_read_out_rule_the_estimators_state():
    text = " ".join((REPO / "raw_data" / "README.md").read_text().split())
    assert rule_text() in text


def test_every_kind_not_read_as_a_sweep_has_a_read_out_rule():
    assert set(READOUT_RULES) == {n for n, k in TEST_KINDS.items() if not k.swept}
    assert methods() == ("dwell", "ringdown") and estimator_of("sweep_fit") is None
    assert estimator_of("dwell").level_readout == ("q_dwell_quad_in", "f_dwell_quad_hz", "zeta_dwell_quad")
    assert level_readout("dwell") == estimator_of("dwell").level_readout and level_readout("ringdown") is None


def _est(method, out):
    return Estimator(method, f"the {method} read-out", lambda read: out)


def test_the_first_read_out_wins_after_the_refusals_before_it_and_none_is_unusable():
    no = Refusal("nothing to read", ("no_a",))
    yes = Readout({"q_in": 1.0, "zeta_res": 0.02, "extra": 3, "f_res_hz": 10.0}, flags=("ok_b",), points=({"q": 1},))
    rule = ReadoutRule("toy", (_est("a", no), _est("b", yes), _est("c", no)))
    est, cols, flags, points = rule.read({"flags": ["read"]})
    assert est.method == "b" and flags == ["read", "no_a", "ok_b"] and points == [{"q": 1}]
    assert list(cols) == ["f_res_hz", "zeta_res", "q_in", "f_res_method", "extra"] and cols["f_res_method"] == "b"
    est, cols, flags, _ = ReadoutRule("toy", (_est("a", no), optional(_est("c", no), "there is one"))).read(
        {"flags": []})
    assert est is None and cols == {} and flags == ["no_a", "unusable"]  # an optional part's absence flags nothing
    assert rule.text == ("A toy run is read by the first of: (1) the a read-out; (2) the b read-out; "
                         "(3) the c read-out; else it is unusable.")
