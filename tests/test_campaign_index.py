"""jointcal._campaign_index: the campaign's manifest read once for the DAG's names, and the
files Snakemake's --summary still plans to remake."""
from __future__ import annotations

import os

import pandas as pd

from jointcal._workflow import campaign_index, pending_outputs
from tests._support.campaign import SMALL_CAMPAIGN, edit_manifest


def test_campaign_index_reads_the_manifest_and_keeps_its_problem(campaign):
    manifest = pd.read_csv(SMALL_CAMPAIGN / "manifest.csv", dtype=str)
    index = campaign_index(SMALL_CAMPAIGN / "manifest.csv")
    assert list(index.run_files) == list(manifest["run_id"]) and index.problem is None
    assert index.run_files[manifest["run_id"][0]] == str(SMALL_CAMPAIGN / manifest["file"][0])
    assert index.assemblies == list(dict.fromkeys(manifest["assembly"])) and index.excitation == "base"
    first = manifest["assembly"][0]
    assert index.assembly_files(first) == [str(SMALL_CAMPAIGN / f) for f in manifest.loc[manifest["assembly"] == first,
                                                                                         "file"]]
    # a listed record that is missing: the names still come through, with read_manifest's sentence kept
    edit_manifest(campaign, lambda d: d.assign(file=d["file"].where(d.index > 0, "gone.csv")))
    broken = campaign_index(campaign / "manifest.csv")
    assert list(broken.run_files) == list(manifest["run_id"]) and broken.excitation == "base"
    assert "gone.csv: the file of run" in broken.problem
    edit_manifest(campaign, lambda d: d.rename(columns={"level_g": "level_V"}))  # the records are not read
    assert campaign_index(campaign / "manifest.csv").excitation == "voltage"


def test_pending_outputs_are_the_planned_files_written_before_the_run(tmp_path):
    old, new, done = tmp_path / "old.csv", tmp_path / "new.csv", tmp_path / "done.csv"
    for f in (old, done, new):
        f.write_text("x\n")
    os.utime(old, (1000.0, 1000.0))
    os.utime(done, (1000.0, 1000.0))
    summary = ("output_file\tdate\trule\tlog-file(s)\tstatus\tplan\n"
               f"{old}\t-\tr\t-\tok\tupdate pending\n{done}\t-\tr\t-\tok\tno update\n"
               f"{new}\t-\tr\t-\tok\tupdate pending\n{tmp_path / 'missing.csv'}\t-\tr\t-\tmissing\tupdate pending\n"
               f"{tmp_path}\t-\tr\t-\tok\tupdate pending\n")
    assert pending_outputs(summary, before=2000.0) == [old]  # not new (written since), done, missing, a folder
    assert pending_outputs("Building DAG of jobs...", before=2000.0) == []
