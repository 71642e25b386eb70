"""Test helpers (not jointcal code): a copy of the repository's workflow to run in, and Snakemake run in it."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from .campaign import REPO

TIMEOUT_S = 1800  # s: one bound for every run, generous for the longest (the whole example workflow, minutes)


def workflow_copy(tmp_path: Path, *, src: bool = False) -> Path:
    """A copy of Snakefile, workflow/ and profiles/ in tmp_path/wf: the working directory of a workflow run.

    With `src`, src/jointcal is copied too, so that a test can edit a module (`snakemake` runs the copy's package).
    """
    work = tmp_path / "wf"
    work.mkdir()
    shutil.copy(REPO / "Snakefile", work)
    ignore = shutil.ignore_patterns("__pycache__")
    for folder in ("workflow", "profiles"):
        shutil.copytree(REPO / folder, work / folder, ignore=ignore, symlinks=True)
    if src:
        shutil.copytree(REPO / "src" / "jointcal", work / "src" / "jointcal", ignore=ignore)
    return work


def snakemake(work: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """``python -m snakemake ARGS`` in the workflow copy `work`, output captured as text.

    jointcal is imported from the copy's own src/ when it has one (``workflow_copy(..., src=True)``), else from this
    repository's src/ (PYTHONPATH), never from whatever jointcal the interpreter has installed.
    """
    src = work / "src" if (work / "src").is_dir() else REPO / "src"
    env = {**os.environ, "PYTHONPATH": str(src)}
    return subprocess.run([sys.executable, "-m", "snakemake", *args], cwd=work, capture_output=True, text=True,
                          env=env, timeout=TIMEOUT_S)


def _edit(path: Path) -> str:
    """Append a comment to a module (a change to its text, not to what it does); return the original."""
    text = path.read_text()
    path.write_text(text + "\n# edited by a test (tests/_support/workflow.py)\n")
    return text
