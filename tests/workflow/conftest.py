"""The one fixture of the workflow runs: a copy of the repository's workflow to run Snakemake in."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests._support.workflow import workflow_copy


@pytest.fixture
def workdir(tmp_path: Path) -> Path:
    """A copy of Snakefile, workflow/ and profiles/ in tmp_path/wf (the working directory of one run; to run it,
    `tests._support.workflow.snakemake`)."""
    return workflow_copy(tmp_path)
