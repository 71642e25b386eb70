"""Shared helpers for modal-stage tests: run envelopes + modal on a campaign folder."""
import json
from pathlib import Path

import numpy as np
import pandas as pd

from jointcal.io import read_manifest, read_run
from jointcal.measure.modal import measure_run
from jointcal.measure.scatter import scatter
from jointcal.models import harmonic_balance


def modal_table(folder, **kw):
    man = read_manifest(Path(folder) / "manifest.csv")
    rows = []
    for row in man.to_dict("records"):
        df = read_run(Path(folder) / row["file"])
        rows.append(measure_run(df, row, modal_kw=kw)[2])
    return pd.DataFrame(rows)


def against_truth(table, truth_path):
    """Relative errors against the truth's harmonic balance at each run's measured amplitude."""
    truth = json.loads(Path(truth_path).read_text())
    out = table.copy()
    for i, r in table.iterrows():
        a = truth["assemblies"][r["assembly"]]
        f, z = harmonic_balance(r["q_in"], a["Fs"], a["KT"], a["chi"], a["beta"], a["k"], a["m"], a["zeta_v"])
        out.loc[i, "f_err"] = r["f_res_hz"] / f - 1
        out.loc[i, "zeta_err"] = r["zeta_phase_resonance"] / z - 1
        out.loc[i, "zeta_hp_err"] = r["zeta_half_power"] / z - 1
    return out
