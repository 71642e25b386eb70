"""ringdown: a run read along its free decay; its row is the largest-amplitude window."""
from __future__ import annotations

from .readout import Estimator, Readout, ReadoutRule, Refusal

__all__ = ["RULE", "WINDOWS", "METHOD", "MIN_DECAY_S"]

METHOD = "ringdown"  # its f_res_method, and backbone.csv's ``test`` of every decay window (a dwell's too)
MIN_DECAY_S = 1.0  # a record this long after the cut holds a ring-down to read (as decay_start asks)


def _top_window(read) -> Readout | Refusal:
    w = read["windows"]
    if w is None or not len(w):  # the read's own flag (shaker_on) says why, where it has one
        return Refusal(f"no free decay of {MIN_DECAY_S:g} s or more", () if read["flags"] else ("no_decay",))
    top = w.loc[w["q_in"].idxmax()]
    return Readout({"f_res_hz": top["f_hz"], "zeta_res": top["zeta"], "q_in": top["q_in"]})


WINDOWS = Estimator(
    METHOD,
    "the largest-amplitude window of its free decay (ringdown): damped-sinusoid fits in sliding windows that "
    "lengthen as the decay nears the noise, one point per window down to the noise floor, read through the force with the modal constant the mode's sweep measured where a force "
    f"reference stays live after the cut (through_force), not read without a decay of {MIN_DECAY_S:g} s or more "
    "(no_decay) or where the shaker stays on and no sweep measured the mode (shaker_on)",
    _top_window)

RULE = ReadoutRule("ringdown", (WINDOWS,))
