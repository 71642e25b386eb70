"""Bad inputs through the workflow: a units or level mistake flagged at ingest reaches
modal_properties.csv as unusable and stays out of the fit, the warnings are kept when an error follows, and a
Windows path or a missing record is named before Snakemake looks for inputs."""
from __future__ import annotations

import shutil

import numpy as np
import pandas as pd
import pytest

from jointcal.calibrate.data import select_modal
from jointcal.units import G_SI  # m/s^2 per g
from tests._support.campaign import edit_manifest, edit_run
from tests._support.ingest import FILE, RUN, _scale, _set, _si
from tests._support.workflow import snakemake


@pytest.mark.slow
def test_workflow_keeps_the_nan_warning_when_an_error_follows(tmp_path, campaign, workdir):
    edit_run(campaign, "run01.csv.gz", _set("base_accel_g", np.nan))
    edit_manifest(campaign, lambda m: m.assign(sample_rate_hz=m["sample_rate_hz"].where(m["run_id"] != "run04",
                                                                                          "12700")))
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "ingest", "--config", f"raw_data={campaign}", f"results={out}")
    assert res.returncode != 0
    log = (out / "logs" / "ingest.log").read_text().splitlines()
    assert len(log) == 2 and "run01.csv.gz: column 'base_accel_g' has 9600 NaN/inf values" in log[0]
    assert "run04.csv.gz: the measured sample rate" in log[1] and "sweep" not in log[0]
    assert "run01.csv.gz" in res.stderr and "run04.csv.gz" in res.stderr
    assert not (out / "ingest" / "runs.csv").exists()


@pytest.mark.slow
def test_workflow_keeps_a_units_mistake_out_of_the_modal_fit(tmp_path, campaign, workdir):
    """Flagged before calibration: a record in m/s^2 and a run whose response alone is in m/s^2 under the g name
    each reach modal_properties.csv as unusable, each flagged with its own sentence (select_modal leaves both out;
    a wrong level takes the same path, see tests/io/test_amplitudes.py). The record in m/s^2 and a clean run's
    file share a basename in two folders (3 runs: CI time)."""
    edit_run(campaign, "run03.csv.gz", _si)
    edit_run(campaign, "run02.csv.gz", _scale("response_accel_g", G_SI))
    edit_manifest(campaign, lambda m: m[m["run_id"].isin(["run01", "run02", "run03"])])
    for rid, folder in (("run01", "a"), ("run03", "b")):
        (campaign / folder).mkdir()
        shutil.move(campaign / f"{rid}.csv.gz", campaign / folder / "run.csv.gz")
        edit_manifest(campaign, lambda m, r=rid, f=folder: m.assign(
            file=m["file"].where(m["run_id"] != r, f"{f}/run.csv.gz")))
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", str(out / "modal" / "modal_properties.csv"),
                    "--config", f"raw_data={campaign}", f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    ingest_log = (out / "logs" / "ingest.log").read_text()
    assert "b/run.csv.gz: base amplitude is 19.6 g" in ingest_log
    assert "run02.csv.gz: below resonance" in ingest_log
    assert "run03: unusable: ingest flagged level:base_accel_g" in (out / "logs" / "modal.log").read_text()
    modal = pd.read_csv(out / "modal" / "modal_properties.csv", keep_default_na=False).set_index("run_id")
    assert modal.loc["run03", "flags"].split(";")[:1] == ["level:base_accel_g"]
    assert modal.loc["run02", "flags"].split(";")[0] == "units:response_accel_g"
    assert "unusable" in modal.loc["run03", "flags"] and "unusable" not in modal.loc["run01", "flags"]
    assert "unusable" in modal.loc["run02", "flags"].split(";")
    assert select_modal(modal.reset_index(), "first").run_id == ("run01",)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["windows path", "missing file"])
def test_workflow_names_a_windows_path_or_a_missing_file_before_looking_for_inputs(tmp_path, example, case,
                                                                                 workdir):
    if case == "windows path":
        edit_manifest(example, lambda m: m.assign(file=m["file"].str.replace("/", "\\")))
        words = f"file 'runs\\{RUN}.csv.gz' is written with a Windows backslash"
    else:
        (example / FILE).unlink()
        words = f"{FILE}: the file of run '{RUN}' listed in manifest.csv (line 2) does not exist"
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "ingest", "--config", f"raw_data={example}", f"results={out}")
    assert res.returncode != 0
    assert "MissingInputException" not in res.stderr and "Traceback" not in res.stderr, res.stderr
    assert f"jointcal: {example / 'manifest.csv'}" in res.stderr or f"jointcal: {example / FILE}" in res.stderr
    assert words in res.stderr
    log = (out / "logs" / "ingest.log").read_text().splitlines()
    assert len(log) == 1 and words in log[0]
    assert not (out / "ingest").exists()
