"""The decision rule (jointcal.discrepancy.rule) on scores set by hand: pairs named only
when they close and no single does, the fast model's floor taken out before 'none', the clauses quoted, a drift
with the sequence, the time simulation's last word."""
import numpy as np

from jointcal.discrepancy import decide
from jointcal.discrepancy.rule import confirm, needs_pairs, pair_names
from jointcal.discrepancy.select import Scored


def _scored(name, score):
    fit = type("F", (), {"E": score, "theta": np.zeros(9)})()
    return Scored(name, fit, score)


def test_two_effects_are_named_only_when_the_pair_closes_and_no_single_does():
    """Forward selection: pairs are tried when the best single leaves the held-out score above the
    'none' threshold; the pair is named when it closes the gap decisively (beats the best single and
    the next pair by the margin), else the single rule stands."""
    singles = [_scored("baseline", 12.0), _scored("fixture_flexibility", 6.0), _scored("quadratic_damping", 7.0),
               _scored("sensor_gain", 11.0)]
    assert needs_pairs(singles)
    assert decide(singles)[:2] == ("unexplained", "low")  # 6 vs 7: not decisive
    names = pair_names(singles, ["fixture_flexibility", "quadratic_damping", "sensor_gain"])
    # the runner-up is not beaten decisively, so it is a base too; each pair once
    assert names == ["fixture_flexibility+quadratic_damping", "fixture_flexibility+sensor_gain",
                     "quadratic_damping+sensor_gain"]
    pairs = [_scored(names[0], 1.4), _scored(names[1], 5.5), _scored(names[2], 6.5)]
    assert decide(singles + pairs)[:2] == ("fixture_flexibility+quadratic_damping", "high")
    close = [_scored(names[0], 1.4), _scored(names[1], 1.8), _scored(names[2], 6.5)]
    assert decide(singles + close)[:2] == ("unexplained", "low")  # two pairs close alike: neither is named
    one = [_scored("baseline", 12.0), _scored("sensor_gain", 1.3), _scored("channel_delay", 9.0)]
    assert not needs_pairs(one) and decide(one)[:2] == ("sensor_gain", "high")
    even = "the response's 2nd harmonic dominates"
    assert decide(singles + pairs, even)[:2] == ("fixture_flexibility+quadratic_damping", "medium")


def test_the_fast_models_floor_is_taken_out_of_the_baseline_before_none():
    """A baseline at 1.9 is 'unexplained' on a perfect fast model, 'none' when 1.2 of it is the fast
    model's own error (sqrt(1.9^2 - 1.2^2) = 1.47 <= 1.5); a floor above the scatter caps confidence."""
    sc = [_scored("baseline", 1.9), _scored("sensor_gain", 1.85), _scored("channel_delay", 1.88)]
    assert decide(sc)[0] == "unexplained"
    assert decide(sc, floor=1.2)[0] == "none"
    strong = [_scored("baseline", 20.0), _scored("sensor_gain", 1.5), _scored("channel_delay", 15.0)]
    assert decide(strong)[1] == "high" and decide(strong, floor=1.2)[1] == "medium"


def test_decide_quotes_the_clauses_of_its_rule_that_decided():
    """The decision carries the rule's text and, of it, the clauses the code applied (what diagnosis.json
    quotes): a named single, 'none', a floor cap, unexplained after pairs, and the time-domain notes."""
    from jointcal.discrepancy.rule import CLAUSES, RULE
    strong = [_scored("baseline", 20.0), _scored("sensor_gain", 1.5), _scored("channel_delay", 15.0)]
    d = decide(strong)
    assert d.rule == RULE and d.applied == (CLAUSES["scores"], CLAUSES["single"])
    assert decide(strong, floor=1.2).applied[-1] == CLAUSES["floor"]
    assert decide([_scored("baseline", 1.2), _scored("sensor_gain", 1.1)]).applied[-1] == CLAUSES["none"]
    alike = [_scored("baseline", 9.0), _scored("sensor_gain", 6.0), _scored("channel_delay", 6.2),
             _scored("sensor_gain+channel_delay", 5.9)]
    assert decide(alike).applied[1:] == (CLAUSES["single"], CLAUSES["pair"], CLAUSES["unexplained"])
    assert all(c in RULE for c in CLAUSES.values()) and RULE.endswith(CLAUSES["name_misses"])
    assert confirm("none", "high", 2.0, 1.9)[2] in CLAUSES and confirm("a", "high", 6.0, 6.5)[2] in CLAUSES


def test_within_the_scatter_only_a_drift_with_the_sequence_is_named():
    """A baseline within the scatter is 'none' even if a candidate halves it, unless that candidate drifts
    with the run sequence (its drift inflates the repeat scatter the baseline is judged by)."""
    quad = [_scored("baseline", 0.63), _scored("quadratic_damping", 0.28), _scored("sensor_gain", 0.6)]
    assert decide(quad)[0] == "none"
    settle = [_scored("baseline", 1.2), _scored("joint_settling", 0.4), _scored("sensor_gain", 1.1)]
    assert decide(settle)[:2] == ("joint_settling", "medium")
    # the drift inflates the scatter: forward selection goes on from it, and a decisive pair is named
    assert needs_pairs(settle) and not needs_pairs(quad)
    with_cubic = [_scored("joint_settling+cubic_stiffening", 0.2), _scored("joint_settling+sensor_gain", 0.38)]
    assert decide(settle + with_cubic)[:2] == ("joint_settling+cubic_stiffening", "medium")
    alike = [_scored("joint_settling+cubic_stiffening", 0.3), _scored("joint_settling+sensor_gain", 0.35)]
    assert decide(settle + alike)[:2] == ("joint_settling", "medium")


def test_the_time_simulation_has_the_last_word():
    assert confirm("none", "high", 0.37, 0.2) == ("none", "high", None)
    assert confirm("none", "high", 0.4, 3.0) == ("none", "high", None)  # before within the scatter
    assert confirm("none", "high", 2.5, 2.2) == ("unexplained", "low", "none_contradicted")
    assert confirm("sensor_gain", "high", 6.0, 1.1) == ("sensor_gain", "high", None)
    assert confirm("sensor_gain", "high", 6.0, 6.5) == ("sensor_gain", "low", "name_not_confirmed")
    # E falls but the recalibrated model still misses: the name holds, high no longer
    assert confirm("quadratic_damping", "high", 6.26, 3.51) == ("quadratic_damping", "medium", "name_misses")
    assert confirm("quadratic_damping", "medium", 6.26, 3.51) == ("quadratic_damping", "medium", None)
    assert confirm("quadratic_damping", "high", 6.26, 1.9) == ("quadratic_damping", "high", None)
