"""The virtual lab's spec (jointcal.synth.spec): a bad spec, given as a mapping or a file, is
one sentence, and nothing is written."""
from __future__ import annotations

import pytest

from jointcal.cli import main
from jointcal.synth import generate, load_spec
from tests._support.ingest import _one_sentence

FIRST = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}


def test_spec_errors_are_one_sentence(tmp_path):
    with pytest.raises(ValueError, match="seed"):
        load_spec({"assemblies": {"a": FIRST}})
    with pytest.raises(ValueError, match="unknown hidden effect"):
        load_spec({"seed": 1, "effect": {"name": "gremlins"}})
    with pytest.raises(ValueError, match="too low"):
        load_spec({"seed": 1, "sample_rate_hz": 4000.0})
    with pytest.raises(ValueError, match="must not live inside"):
        generate({"seed": 1}, tmp_path / "c", tmp_path / "c" / "truth.json")


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
