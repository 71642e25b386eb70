"""Writers that never leave half a file (jointcal.io._atomic), and write_run's own checks."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.io import write_bytes_atomic, write_csv_atomic, write_json_atomic, write_run


def test_write_run_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match="one length"):
        write_run(tmp_path / "a.csv", [0.0, 1.0], [0.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="suffix"):
        write_run(tmp_path / "a.txt", [0.0], [0.0], [0.0])


def _listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_atomic_writers_create_parents_and_leave_no_temp(tmp_path):
    df = pd.DataFrame({"a": [1.5, 2.0], "b": ["x", "y"]})
    out = write_csv_atomic(df, tmp_path / "deep" / "er" / "t.csv")
    pd.testing.assert_frame_equal(pd.read_csv(out), df)
    write_json_atomic({"x": np.float64(1.5), "v": np.arange(3), "p": Path("a/b")}, tmp_path / "deep" / "j.json")
    assert json.loads((tmp_path / "deep" / "j.json").read_text()) == {"x": 1.5, "v": [0, 1, 2], "p": "a/b"}
    write_bytes_atomic(b"abc", tmp_path / "deep" / "b.bin")
    write_bytes_atomic(b"new", tmp_path / "deep" / "b.bin")
    assert (tmp_path / "deep" / "b.bin").read_bytes() == b"new"
    assert _listing(tmp_path / "deep") == ["b.bin", "er", "j.json"]
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask


def test_json_writer_failing_midway_keeps_old_file(tmp_path):
    target = tmp_path / "state.json"
    target.write_text('{"old": true}\n')
    with pytest.raises(TypeError):
        write_json_atomic({"a": list(range(1000)), "b": object()}, target)
    assert target.read_text() == '{"old": true}\n'
    assert _listing(tmp_path) == ["state.json"]


def test_csv_writer_failing_midway_keeps_old_file(tmp_path, monkeypatch):
    target = tmp_path / "runs.csv"
    target.write_text("old\n")

    def broken_to_csv(self, fh, **kwargs):
        fh.write("half a ta")
        raise OSError("disk full")

    monkeypatch.setattr(pd.DataFrame, "to_csv", broken_to_csv)
    with pytest.raises(OSError, match="disk full"):
        write_csv_atomic(pd.DataFrame({"a": [1]}), target)
    assert target.read_text() == "old\n"
    assert _listing(tmp_path) == ["runs.csv"]
