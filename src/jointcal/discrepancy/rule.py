"""The decision on the held-out scores (`select`): a name, 'none' or 'unexplained', and the rule's own words;
and when forward selection goes on to pairs, and which (`needs_pairs`, `pair_bases`, `pair_names`).

The rule is written once, clause by clause (`CLAUSES`, joined into `RULE`): `decide` and
`confirm` name the clauses they applied (`Decision.applied`), so the text diagnosis.json
quotes is the one the code ran. The fast model's floor F is taken out of the baseline's
score before the 'none' test: S_b' = sqrt(max(S_b^2 - F^2, 0)).
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..effects import EFFECTS, JOIN, effects_of

if TYPE_CHECKING:
    from .select import Scored

__all__ = ["NONE_E", "CLOSE_FRACTION", "MARGIN", "WITHIN_SCATTER", "FLOOR_HIGH", "HIGH_SCORE", "NONE_HIGH", "CLAUSES", "RULE", "Decision",
           "decide", "confirm", "needs_pairs", "pair_bases", "pair_names"]

NONE_E = 1.5
CLOSE_FRACTION = 0.6
MARGIN = 0.7
WITHIN_SCATTER = 0.5
FLOOR_HIGH = 1.0  # a fast-model floor above this (the repeat scatter) caps every confidence at medium
HIGH_SCORE = 2.0  # a name is held with confidence high only at a held-out score at or below this
NONE_HIGH = 0.8  # a 'none' is high unless the best single effect scores below this fraction of the baseline

CLAUSES: dict[str, str] = {
    "scores": ("Scores S are held-out fast-model E (1 = the repeat scatter), S_b the baseline's, F the fast model's "
               "floor."),
    "none": (f"'none' if sqrt(S_b^2 - F^2) <= {NONE_E} (high unless the best single effect scores below "
             f"{NONE_HIGH} x S_b: then medium)"),
    "drift": (f"(unless the best single effect changes with the run sequence, whose drift inflates the repeat "
              f"scatter, and scores <= {WITHIN_SCATTER} x S_b and <= {MARGIN} x the runner-up: named, medium; "
              f"forward selection then goes on from it, and a pair with it that scores <= {MARGIN} x it and x the "
              "next pair is named instead, medium)."),
    "single": (f"Otherwise a single effect is named if it closes >= {CLOSE_FRACTION:.0%} of the baseline's excess "
               f"over 1 and scores <= {MARGIN} x the runner-up (high when its score <= {HIGH_SCORE:g})."),
    "pair": (f"If the best single scores above {NONE_E}, effects are added to it one at a time (forward "
             f"selection); a pair is named instead when it closes >= {CLOSE_FRACTION:.0%} of the excess, scores <= "
             f"{MARGIN} x the best single and <= {MARGIN} x the next pair (high when its score <= {HIGH_SCORE:g})."),
    "unexplained": "Otherwise unexplained.",
    "outside": (f"A fingerprint no library effect leaves (a dominant even harmonic) keeps a name only at score <= "
                f"{HIGH_SCORE:g}, with confidence medium;"),
    "floor": f"a floor F > {FLOOR_HIGH} caps confidence at medium.",
    "none_contradicted": (f"A 'none' the time simulation contradicts (E > {NONE_E} before and after the refit) "
                          "becomes unexplained."),
    "name_not_confirmed": (f"A name whose time-domain E does not fall, from above {NONE_E}, keeps confidence "
                           "low."),
    "name_misses": (f"A name whose recalibrated model's time-domain E stays above {HIGH_SCORE:g} is held at most "
                    "medium: it closes part of the gap, not all of it."),
}
RULE = " ".join(CLAUSES.values())


class Decision(NamedTuple):
    """What `decide` found: the effect(s) or 'none'/'unexplained', its confidence, the candidates
    ranked by score, the whole rule (`RULE`) and the clauses of it that decided (their text)."""

    effect: str
    confidence: str
    ranked: list
    rule: str
    applied: tuple[str, ...]


def _ranked(scored: Sequence[Scored], pairs: bool) -> list[Scored]:
    return sorted((s for s in scored if s.name != "baseline" and (len(effects_of(s.name)) > 1) == pairs),
                  key=lambda s: s.score)


def _above_floor(score: float, floor: float) -> float:
    return float(np.sqrt(max(score**2 - floor**2, 0.0)))


def decide(scored: Sequence[Scored], outside: str | None = None, *, floor: float = 0.0) -> Decision:
    """The decision by `RULE`: effect(s) or 'none'/'unexplained', confidence, candidates ranked by score,
    and the rule's text with the clauses that decided.

    scored : the baseline, single effects and any pairs ('a+b'). outside : a fingerprint no
    library effect leaves (`fingerprints.outside_library`), or None. floor : the fast model's
    own error F (E units).
    """
    base = next(s for s in scored if s.name == "baseline")
    singles, pairs = _ranked(scored, False), _ranked(scored, True)
    ranked = sorted(singles + pairs, key=lambda s: s.score)
    s1 = singles[0].score if singles else np.inf
    s2 = singles[1].score if len(singles) > 1 else np.inf
    name, conf, keys = _rule(base.score, s1, s2, singles, pairs, outside, floor)
    if conf == "high" and floor > FLOOR_HIGH:
        conf = "medium"
        keys += ("floor",)
    return Decision(name, conf, ranked, RULE, tuple(CLAUSES[k] for k in ("scores", *keys)))


def _drifts(name: str) -> bool:
    """Whether the model changes with the run sequence: its drift inflates the repeat scatter it is judged by."""
    return any(EFFECTS[e].sequence_dependent for e in effects_of(name))


def _closes(sb: float, s: float) -> bool:
    return sb - s >= CLOSE_FRACTION * (sb - 1.0)


def _within_scatter_drift(sb: float, singles: Sequence[Scored], outside) -> bool:
    """The within-scatter branch of the rule: the best single drifts with the sequence and halves the baseline."""
    s1 = singles[0].score if singles else np.inf
    s2 = singles[1].score if len(singles) > 1 else np.inf
    return bool(singles) and _drifts(singles[0].name) and s1 <= WITHIN_SCATTER * sb and s1 <= MARGIN * s2 and not outside


def _pair_wins(pairs: Sequence[Scored], s1: float) -> bool:
    """The best pair beats the best single and the next pair by the margin."""
    p1 = pairs[0].score
    p2 = pairs[1].score if len(pairs) > 1 else np.inf
    return p1 <= MARGIN * s1 and p1 <= MARGIN * p2


def _rule(sb, s1, s2, singles, pairs, outside, floor) -> tuple[str, str, tuple[str, ...]]:
    """(name, confidence, the keys of the `CLAUSES` applied)."""
    out = ("outside",) if outside else ()
    if _above_floor(sb, floor) <= NONE_E:
        if _within_scatter_drift(sb, singles, outside):
            if pairs and _drifts(pairs[0].name) and _pair_wins(pairs, s1):
                return pairs[0].name, "medium", ("none", "drift")
            return singles[0].name, "medium", ("none", "drift")
        return "none", "high" if (not singles or s1 > NONE_HIGH * sb) else "medium", ("none",)
    if pairs:
        p1 = pairs[0].score
        if _closes(sb, p1) and _pair_wins(pairs, s1) and not (outside and p1 > HIGH_SCORE):
            return pairs[0].name, "high" if (p1 <= HIGH_SCORE and not outside) else "medium", ("pair", *out)
    if not singles:
        return "unexplained", "low", ("unexplained",)
    if _closes(sb, s1) and s1 <= MARGIN * s2 and not (outside and s1 > HIGH_SCORE):
        return singles[0].name, "high" if (s1 <= HIGH_SCORE and not outside) else "medium", ("single", *out)
    return "unexplained", "low", ("single", "pair", "unexplained", *out) if pairs else ("single", "unexplained", *out)


def confirm(effect: str, confidence: str, e_before: float, e_after: float) -> tuple[str, str, str | None]:
    """The time simulation's word on a decision: (effect, confidence, note) by the end of `RULE`
    (the note is the key of the clause applied, `CLAUSES[note]`).

    e_before, e_after : the time-domain E of the calibrated model and of the decided model
    recalibrated. 'none' with both above `NONE_E` is contradicted (-> 'unexplained', note
    'none_contradicted'); a name whose E does not fall, from above `NONE_E`, is not confirmed
    (confidence 'low', note 'name_not_confirmed'); a name whose E falls but stays above `HIGH_SCORE`
    is held at most 'medium' (note 'name_misses').
    """
    if effect == "none" and min(e_before, e_after) > NONE_E:
        return "unexplained", "low", "none_contradicted"
    if effect not in ("none", "unexplained") and e_after >= e_before and e_before > NONE_E:
        return effect, "low", "name_not_confirmed"
    if effect not in ("none", "unexplained") and e_after > HIGH_SCORE and confidence == "high":
        return effect, "medium", "name_misses"
    return effect, confidence, None


def needs_pairs(scored: Sequence[Scored], floor: float = 0.0) -> bool:
    """Whether forward selection goes on to pairs: the baseline misses and no single effect brings the
    held-out score down to `NONE_E`; or the single named is a drift with the run sequence found within
    the scatter (that scatter is then partly the drift's, and judged without it a second effect may show)."""
    base = next(s for s in scored if s.name == "baseline")
    singles = _ranked(scored, False)
    if not singles:
        return False
    if _above_floor(base.score, floor) > NONE_E:
        return singles[0].score > NONE_E
    return _within_scatter_drift(base.score, singles, None)


def pair_bases(scored: Sequence[Scored]) -> list[str]:
    """The single effects forward selection extends: the best, and the runner-up when the best does not
    beat it decisively."""
    singles = _ranked(scored, False)
    return [singles[0].name] + ([singles[1].name] if len(singles) > 1 and singles[0].score > MARGIN * singles[1].score
                                else [])


def pair_names(scored: Sequence[Scored], library: Sequence[str]) -> list[str]:
    """Pairs to try: each base (`pair_bases`) plus each other effect of `library` (a pair is named by the
    order its effects were added)."""
    out, seen = [], set()
    for b in pair_bases(scored):
        for e in library:
            key = frozenset((b, e))
            if e != b and key not in seen:
                seen.add(key)
                out.append(f"{b}{JOIN}{e}")
    return out
