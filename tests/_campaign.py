"""Test helpers (not jointcal code): where the small campaign lives and how to break a copy."""
from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from jointcal.io import read_run

DATA = Path(__file__).parent / "data"
SMALL_CAMPAIGN = DATA / "small_campaign"
REPO = Path(__file__).parents[1]


def edit_manifest(campaign: Path, edit: Callable[[pd.DataFrame], pd.DataFrame | None]) -> None:
    """Apply `edit` to the manifest (text columns; it returns a new table or edits in place)."""
    df = pd.read_csv(campaign / "manifest.csv", dtype=str, keep_default_na=False)
    df = df if (new := edit(df)) is None else new
    df.to_csv(campaign / "manifest.csv", index=False)


def edit_run(campaign: Path, file: str, edit: Callable[[pd.DataFrame], pd.DataFrame | None]) -> None:
    """Apply `edit` to run `file`'s table (it returns a new table or edits in place); write CSV."""
    df = read_run(campaign / file)
    df = df if (new := edit(df)) is None else new
    df.to_csv(campaign / file, index=False, float_format="%.9g")


def workflow_copy(tmp_path: Path) -> Path:
    """A copy of Snakefile, workflow/ and profiles/ in tmp_path/wf: the working directory of a workflow run."""
    work = tmp_path / "wf"
    work.mkdir()
    shutil.copy(REPO / "Snakefile", work)
    for folder in ("workflow", "profiles"):
        shutil.copytree(REPO / folder, work / folder, ignore=shutil.ignore_patterns("__pycache__"))
    return work
