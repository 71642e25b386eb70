"""Real records from another lab, end to end (opt-in: ``pytest -m acceptance``; skipped without the data).

The UNESP-BERT bolted beam's mode 1 (six voltage-driven up chirps at eta 200-600; SHM Lab, UNESP
Ilha Solteira, non-commercial research use) lives outside this repository, in
../shared/real/unesp-bert-mode1 beside it, and is never copied in. The whole workflow runs on it
with the default config: the model kind follows the excitation (one mode, per unit modal mass, its
bounds from the data), the calibrated curve passes within 0.2% of every run's (q_in, f_res_hz), and the
discrepancy stage tries the modal library on it.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate import DEFAULT_BOUNDS
from jointcal.posterior.fit import P_REJECT
from jointcal.report.summary import fmt
from jointcal.report.verdict import HOLDS_E
from tests._support.workflow import snakemake

REAL = Path(__file__).resolve().parents[3] / "shared" / "real" / "unesp-bert-mode1"

pytestmark = [pytest.mark.acceptance,
              pytest.mark.skipif(not (REAL / "manifest.csv").is_file(),
                                 reason=f"the real records are not at {REAL} (they are not part of the repository)")]


def test_a_voltage_driven_real_campaign_runs_end_to_end_with_the_default_config(tmp_path, workdir):
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "--config", f"raw_data={REAL}", f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    best = json.loads((out / "calibration" / "bert_5Nm" / "m18" / "ga_best.json").read_text())
    assert best["model_kind"] == "modal" and best["excitation"] == "voltage" and best["per_unit_modal_mass"]
    assert best["m"] == 1.0
    assert all(best["bounds"][p] != DEFAULT_BOUNDS[p] for p in ("Fs", "KT", "k"))  # from the data
    modal = pd.read_csv(out / "modal" / "modal_properties.csv")
    assert (modal["f_res_method"] == "sweep_fit").all()
    curve = pd.read_csv(out / "calibration" / "bert_5Nm" / "m18" / "model_curves.csv")
    curve = curve[curve["model"] == best["model"]]
    f_model = np.interp(np.log(modal["q_in"]), np.log(curve["q_in"]), curve["f_hz"])
    err = f_model / modal["f_res_hz"] - 1
    print("\ncalibrated curve vs each run's (q_in, f_res_hz):", ", ".join(f"{100 * e:+.3f}%" for e in err))
    assert np.abs(err).max() < 2e-3
    summary = json.loads((out / "validation" / "bert_5Nm" / "m18" / "summary.json").read_text())
    assert np.isfinite(summary["E"]) and "modal constant" in summary["words"]
    assert any((out / "validation" / "bert_5Nm" / "m18" / "envelopes" / "traces").glob("*.csv"))
    assert "per unit modal mass" in (out / "posterior" / "bert_5Nm" / "m18" / "constraints.txt").read_text()
    diag = json.loads((out / "discrepancy" / "bert_5Nm" / "m18" / "diagnosis.json").read_text())
    assert diag["model_kind"] == "modal" and diag["level_unit"] == "V"  # the modal library, on the voltage drive
    assert "sensor_gain" not in {c["name"] for c in diag["candidates"]}
    print(f"discrepancy: {diag['effect']} ({diag['confidence']}), E {diag['metric_before']:.3g} -> "
          f"{diag['metric_after']:.3g}, floor {diag['fast_model_floor']['E']}, {diag['seconds']:.0f} s")
    # the verdict's first answer agrees with the chi-square it shows (and with E): Yes only when both pass
    page = (out / "report" / "summary.html").read_text()
    answer = re.search(r"reproduce the measured envelopes\?</b> <b>(Yes|No)</b>", page).group(1)
    with np.load(out / "posterior" / "bert_5Nm" / "m18" / "chain.npz") as z:
        p, chi2, dof = float(z["fit_p"]), float(z["fit_chi2"]), int(z["fit_dof"])
    print(f"verdict: {answer}; chi-square {chi2:.4g} for {dof} dof, p = {p:.2g}; E = {summary['E']:.3g}")
    assert (answer == "Yes") == (p >= P_REJECT and summary["E"] <= HOLDS_E)
    assert f"chi-square {fmt(chi2)} for {dof} degrees of freedom" in page  # the test the answer stands on


DWELL = REAL.parent / "unesp-bert-dwell-mode1"


@pytest.mark.skipif(not DWELL.is_dir(), reason=f"the real dwell records are not at {DWELL}")
def test_the_real_dwell_campaign_runs_end_to_end_with_the_default_config(tmp_path, workdir):
    # the lab's five Test.Lab exports as they were handed over, in a manifest that points at them (nothing copied):
    # the ring-downs after each dwell are read, calibrated, validated as they were done, and diagnosed
    from tests.benchmarks.real_dwell_campaign import write_campaign

    camp = tmp_path / "campaign"
    write_campaign(camp)
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "--config", f"raw_data={camp}", f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    bb = pd.read_csv(out / "modal" / "backbone.csv")
    rd = bb[bb["test"] == "ringdown"]
    assert rd["run_id"].nunique() == 5 and (rd.groupby("run_id")["q_in"].agg(lambda q: np.log10(q.max() / q.min()))
                                            > 1.5).all()
    summary = json.loads((out / "validation" / "bert" / "m18" / "summary.json").read_text())
    assert np.isfinite(summary["E"]) and "free decays" in summary["words"]
    diag = json.loads((out / "discrepancy" / "bert" / "m18" / "diagnosis.json").read_text())
    print(f"\nvalidation E {summary['E']:.3g} (f {summary['E_f']:.3g}, zeta {summary['E_zeta']:.3g}); discrepancy: "
          f"{diag['effect']} ({diag.get('confidence')}), E {diag['metric_before']:.3g} -> {diag['metric_after']:.3g}")
    page = (out / "report" / "summary.html").read_text()
    assert re.search(r"reproduce the measured envelopes\?</b> <b>(Yes|No)</b>", page)
