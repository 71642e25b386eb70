"""The manifest and the table readers (jointcal.io._manifest): every row checked, a delimiter,
trailing commas, empty rows or a record that is not CSV text guessed, each mistake one sentence naming the file,
the line and the fix."""
from __future__ import annotations

import zipfile

import numpy as np
import pandas as pd
import pytest

from jointcal.io import read_manifest, read_run
from tests._support.campaign import edit_manifest
from tests._support.ingest import FILE, OTHER, RUN, _ingest, _one_sentence, _raises, _stopped


def test_manifest_types(small_campaign):
    m = read_manifest(small_campaign / "manifest.csv")
    assert list(m["run_id"]) == ["run01", "run02", "run03", "run04", "run05"]
    assert m["sequence"].dtype == np.int64 and m["level_g"].dtype == np.float64
    assert set(m["direction"]) == {"up", "down"}


@pytest.mark.parametrize("rid, bad", [("first/run02", "'/'"), ("run 02", "' '"), ("../run02", "'/'")])
def test_run_id_must_be_a_safe_file_name(campaign, rid, bad):
    edit_manifest(campaign, lambda m: m.assign(run_id=m["run_id"].where(m["run_id"] != "run02", rid)))
    _raises(campaign, "manifest.csv: line 3", f"run_id {rid!r} is not a safe file name", bad,
            "use letters, digits")


@pytest.mark.parametrize("sep, name", [(";", "semicolons"), ("\t", "tabs")])
def test_manifest_delimiter_is_guessed_and_named(campaign, sep, name):
    m = pd.read_csv(campaign / "manifest.csv", dtype=str)
    m.to_csv(campaign / "manifest.csv", sep=sep, index=False, decimal=",")
    _raises(campaign, "manifest.csv", f"separated by {name}", "save it as comma-separated text")


def test_run_file_delimiter_is_guessed_and_named(campaign):
    read_run(campaign / "run03.csv.gz").to_csv(campaign / "run03.csv.gz", sep=";", index=False, decimal=",")
    _raises(campaign, "run03.csv.gz", "separated by semicolons", "save it as comma-separated text")


def test_one_record_under_two_spellings_is_one_record(example, capsys):
    edit_manifest(example, lambda m: pd.concat([m, m.iloc[[0]].assign(run_id="again", sequence="13",
                                                                        file=f"./{FILE}")]))
    _stopped(example, capsys, "manifest.csv: lines 2, 4", f"name one file, as '{FILE}' and './{FILE}'",
             "give each run its own record file")


def test_spreadsheet_trailing_empty_rows_are_left_out_with_a_note(example, capsys):
    with open(example / "manifest.csv", "a") as fh:
        fh.write(",,,,,,,,,\n" * 3)
    code, err, runs = _ingest(example, capsys)
    assert code == 0 and list(runs.index) == [RUN, OTHER] and (runs["flags"] == "").all(), err
    _one_sentence(err.splitlines()[0].removeprefix("jointcal: warning: "), "manifest.csv: lines 4-6 are empty",
                  "delete them from the manifest")


@pytest.mark.parametrize("where", ["manifest", "run"])
def test_a_trailing_comma_on_every_line_is_named(example, capsys, where):
    path = example / ("manifest.csv" if where == "manifest" else FILE)
    if where == "manifest":
        lines = path.read_text().splitlines()
        path.write_text("".join(f"{line},\n" for line in lines))
    else:
        read_run(path).to_csv(path, index=False, float_format="%.9g")
        import gzip

        text = gzip.decompress(path.read_bytes()).decode().splitlines()
        path.write_bytes(gzip.compress("".join(f"{line},\n" for line in text).encode()))
    _stopped(example, capsys, path.name, "every line ends with a comma, which adds an empty last column",
             "remove the trailing commas")


def test_trailing_commas_on_the_data_lines_only_are_named(example, capsys):
    """pandas would silently shift the columns (the first becomes the index)."""
    path = example / "manifest.csv"
    lines = path.read_text().splitlines()
    path.write_text(lines[0] + "\n" + "".join(f"{line},\n" for line in lines[1:]))
    _stopped(example, capsys, "manifest.csv", "every data line ends with a comma", "remove the trailing commas")


@pytest.mark.parametrize("content, words", [
    ("gzip", ["first_01_1g_up.csv: it is gzip-compressed but named .csv",
              "rename it first_01_1g_up.csv.gz (also in the manifest's file column) or decompress it"]),
    ("xlsx", ["first_01_1g_up.csv: it is a zip archive (an Excel workbook?) but named .csv",
              "save it from the spreadsheet as 'CSV UTF-8 (comma delimited)'"]),
])
def test_a_record_that_is_not_csv_text_is_named(example, capsys, content, words):
    plain = example / "runs" / f"{RUN}.csv"
    if content == "gzip":
        (example / FILE).rename(plain)
    else:
        with zipfile.ZipFile(plain, "w") as z:
            z.writestr("xl/workbook.xml", "<workbook/>")
    edit_manifest(example, lambda m: m.assign(file=m["file"].where(m["run_id"] != RUN, f"runs/{RUN}.csv")))
    _stopped(example, capsys, *words)


@pytest.mark.parametrize("case", ["windows path", "missing file"])
def test_a_windows_path_or_a_missing_file_is_named_when_the_manifest_is_read(example, capsys, case):
    if case == "windows path":
        edit_manifest(example, lambda m: m.assign(file=m["file"].where(m["run_id"] != RUN, f"runs\\{RUN}.csv.gz")))
        words = [f"manifest.csv: line 2 (run_id '{RUN}'): file 'runs\\{RUN}.csv.gz'", "Windows backslash ('\\')",
                 f"write it with '/' ({FILE})"]
    else:
        (example / FILE).unlink()
        words = [FILE, f"the file of run '{RUN}' listed in manifest.csv (line 2) does not exist",
                 "add the file or correct its name"]
    _stopped(example, capsys, *words)
