"""jointcal._workflow, the workflow's parse-time helpers: a stage's code hash follows its imports
(an edit of measure/peaks.py reruns no stage before modal), and a config key or value given wrong is named in
one line."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

from jointcal import _workflow
from jointcal._workflow import config_problem, stage_sources
from tests._support.campaign import REPO
from tests._support.workflow import _edit

SCRIPTS = REPO / "workflow" / "scripts"
SCHEMA = REPO / "workflow" / "schemas" / "config.schema.yaml"


def _names(files: list[Path]) -> set[str]:
    return {f.relative_to(REPO / "src" / "jointcal").as_posix() for f in files[1:]}


def test_stage_sources_follow_imports_through_the_package():
    assert stage_sources(SCRIPTS / "modal.py")[0] == SCRIPTS / "modal.py"  # the script's own text counts too
    modal = _names(stage_sources(SCRIPTS / "modal.py"))
    assert {"measure/modal.py", "measure/envelopes.py", "io/__init__.py", "io/_checks.py", "__init__.py"} <= modal
    assert not any(n.startswith(("calibrate/", "posterior/", "report/")) for n in modal)
    assert "measure/modal.py" not in _names(stage_sources(SCRIPTS / "ingest.py"))
    assert "measure/modal.py" not in _names(stage_sources(SCRIPTS / "envelopes.py"))
    # `from ..calibrate.space import ...` in report/calibration.py, and the packages' __init__ files
    figures = _names(stage_sources(SCRIPTS / "calibration_figures.py"))
    assert {"report/__init__.py", "report/calibration.py", "calibrate/__init__.py", "calibrate/space.py"} <= figures


def test_an_edit_of_measure_peaks_changes_no_stage_hash_before_modal(tmp_path, monkeypatch):
    """The hash the rules pass as params (common.smk's source_hash: `stage_hash` of the script), on a copy of the
    package whose measure/peaks.py is edited: ingest, envelopes and the kernels keep theirs, modal's changes."""
    before_modal = [re.search(r'script:\s*"\.\./scripts/(\w+\.py)"', block).group(1)
                    for smk in ("ingest", "envelopes", "kernels")
                    for block in re.split(r"(?m)^(?=rule )", (REPO / "workflow" / "rules" / f"{smk}.smk").read_text())
                    if "script:" in block]
    assert {"ingest.py", "envelopes.py", "kernels.py"} <= set(before_modal)
    pkg = tmp_path / "jointcal"
    shutil.copytree(REPO / "src" / "jointcal", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(_workflow, "_ROOT", pkg.resolve())
    hashes = {s: _workflow.stage_hash(SCRIPTS / s) for s in [*before_modal, "modal.py"]}
    _edit(pkg / "measure" / "peaks.py")
    assert {s: _workflow.stage_hash(SCRIPTS / s) for s in before_modal} == {s: hashes[s] for s in before_modal}
    assert _workflow.stage_hash(SCRIPTS / "modal.py") != hashes["modal.py"]  # the hash does see the edit


def test_every_stage_hashed_in_one_pass_is_the_sha256_of_its_own_sources(tmp_path, monkeypatch):
    """common.smk hashes every script in one pass (`stage_hashes`, the files they share read once): each hash is
    the SHA-256 of that script's own sources, path and text, computed here file by file; on a copy of the package
    an edit of a module one stage imports changes that stage's hash and no other's."""
    import hashlib

    pkg = tmp_path / "jointcal"
    shutil.copytree(REPO / "src" / "jointcal", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(_workflow, "_ROOT", pkg.resolve())
    scripts = sorted(SCRIPTS.glob("*.py"))

    def by_hand(script):
        h = hashlib.sha256()
        for f in stage_sources(script):
            rel = f.relative_to(pkg.resolve()).as_posix() if f.is_relative_to(pkg.resolve()) else f.name
            h.update(rel.encode() + b"\0" + f.read_bytes() + b"\0")
        return h.hexdigest()[:16]

    before = _workflow.stage_hashes(scripts)
    assert before == [by_hand(s) for s in scripts] and len(set(before)) == len(scripts)
    _edit(pkg / "design" / "candidates.py")  # the design stage's alone
    after = dict(zip((s.name for s in scripts), _workflow.stage_hashes(scripts)))
    changed = {n for n, h in zip((s.name for s in scripts), before) if after[n] != h}
    assert changed == {"design.py"}


def test_typo_in_a_nested_key_names_the_nearest_valid_key():
    config = {"raw_data": "raw_data", "calibrate": {"bounds": {"Fs": [1, 10]}, "populaton": 40}}
    msg = config_problem(config, SCHEMA)
    assert msg is not None and "\n" not in msg
    assert "'calibrate.populaton'" in msg and "did you mean 'calibrate.population'?" in msg
    assert "did you mean 'resul" in config_problem({"resuls": "out"}, SCHEMA)


def test_nested_config_given_as_text_is_converted_or_named_in_one_line():
    config = {"posterior": {"ball": "0.005", "rel_std_floor": {"frequency": "1e-3"}},  # as --config leaves them
              "calibrate": {"bounds": {"Fs": ["1", "100"]}, "model": "qsma"}}
    assert config_problem(config, SCHEMA) is None
    assert config["posterior"]["ball"] == 0.005 and config["posterior"]["rel_std_floor"]["frequency"] == 1e-3
    assert config["calibrate"]["bounds"]["Fs"] == [1, 100] and config["calibrate"]["model"] == "qsma"
    msg = config_problem({"posterior": {"ball": "small"}}, SCHEMA)
    assert msg.startswith("config 'posterior.ball': 'small' is not of type 'number'")
    assert "--configfile my.yaml" in msg and "\n" not in msg


def _settings(node, path=()):
    """Every leaf setting of a config (path, value), a list being one setting."""
    if isinstance(node, dict) and node:
        for k, v in node.items():
            yield from _settings(v, (*path, k))
    else:
        yield path, node


def test_every_setting_given_on_the_command_line_as_the_readme_shows_is_read_as_its_value():
    """Each setting of config.yaml given as ``--config 'section={key: value}'`` (Snakemake's own parser,
    which leaves nested values as text) is read back as the value the config file gives, or stops in one
    sentence; a list-or-null setting (modal.mode_hz) takes a number, a list and null."""
    import yaml
    from snakemake.cli import parse_config
    from snakemake.utils import update_config

    defaults = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    cases = [(p, v) for p, v in _settings(defaults)]
    cases += [(("modal", "mode_hz"), 95.0), (("modal", "mode_hz"), [18.6, 95.0]), (("modal", "mode_hz"), None)]
    assert len(cases) > 40  # the walk reached the nested sections
    for path, value in cases:
        text = yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()
        for key in reversed(path[1:]):
            text = f"{{{key}: {text}}}"
        config = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
        update_config(config, parse_config([f"{path[0]}={text}"]))
        assert config_problem(config, SCHEMA) is None, (path, text)
        got = config
        for key in path:
            got = got[key]
        assert got == value, (path, text, got)
    msg = config_problem({"modal": {"mode_hz": ["95", "high"]}}, SCHEMA)
    assert msg is not None and "\n" not in msg and "modal.mode_hz" in msg
