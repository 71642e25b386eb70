"""The virtual lab's spec (jointcal.synth.spec): a malformed spec file is one sentence
naming it, and nothing is written."""
from __future__ import annotations

import pytest

from jointcal.cli import main
from tests._support.ingest import _one_sentence


@pytest.mark.parametrize("text, words", [
    ("seed: 1\nsweep:\n  f_start_hz: 700\n f_stop_hz: 900\n", ["not valid YAML at line 4", "fix the syntax there"]),
    ("seed: 1\nseries:\n  level_g: 1.0\n  repeats: 1\n", ["series must be a list", "DEFAULT_SPEC"]),
    ("seed: 1\nseries: [1.0]\n", ["series item 1 must be a mapping", "level_g: 1.0"]),
    ("seed: 1\nsweep: 700\n", ["sweep must be a mapping of keys"]),
    ('{"seed": 1,}', ["not valid JSON at line 1", "fix the syntax there"]),
])
def test_malformed_synth_spec_is_one_sentence(tmp_path, capsys, text, words):
    spec = tmp_path / ("spec.json" if text.startswith("{") else "spec.yaml")
    spec.write_text(text)
    out = tmp_path / "camp"
    assert main(["synth", str(spec), str(out), "--truth", str(tmp_path / "truth.json")]) == 2
    err = capsys.readouterr().err.strip()
    _one_sentence(err, str(spec), *words)
    assert not out.exists() and not (tmp_path / "truth.json").exists()
