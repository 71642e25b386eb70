"""dwell: a run read at its steady state, with its level's modal constant; else along its ring-down after the cut."""
from __future__ import annotations

import numpy as np

from .readout import Estimator, Readout, ReadoutRule, Refusal, optional
from .ringdown import MIN_DECAY_S, WINDOWS

__all__ = ["RULE", "STEADY"]

LEVEL_READOUT = ("q_dwell_quad_in", "f_dwell_quad_hz", "zeta_dwell_quad")  # a level's phase resonance


def _steady_point(read) -> Readout | Refusal:
    d = read.get("dwell")
    if d is None or not np.isfinite(d["f_hz"]):
        return Refusal("its level's dwells give no modal constant", tuple(d["fit"]["flags"]) if d else ())
    p, fit = read["point"], d["fit"]
    point = {"run_id": read["row"]["run_id"], "mode": read["mode"], "test": STEADY.method,
             **{k: d[k] for k in ("q_in", "f_hz", "zeta")}}
    return Readout({"f_res_hz": d["f_hz"], "zeta_res": d["zeta"], "q_in": d["q_in"], "dwell_hz": p["f_hz"],
                    "dwell_ratio_re": p["ratio"].real, "dwell_ratio_im": p["ratio"].imag,
                    "f_dwell_quad_hz": fit["f_hz"], "zeta_dwell_quad": fit["zeta"], "q_dwell_quad_in": fit["q_in"],
                    "dwell_residual": fit["residual"], "dwell_constant_re": fit["A"].real,
                    "dwell_constant_im": fit["A"].imag},
                   flags=(*p["flags"], *fit["flags"]), points=(point,))


STEADY = Estimator(
    "dwell",
    "its steady point (dwell): the response over the reference at dwell_hz, with the modal constant of its "
    "level's three or more dwells (force-referenced: the one the mode's sweep measured) giving its natural "
    "frequency and damping at the amplitude it reached (and the level's phase resonance), not read without one "
    "(few_dwells)",
    _steady_point, level_readout=LEVEL_READOUT)

RULE = ReadoutRule("dwell", (STEADY, optional(WINDOWS, f"the record goes on for {MIN_DECAY_S:g} s or more after "
                                                       "its drive is cut")))
