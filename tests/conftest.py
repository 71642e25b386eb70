"""Shared fixtures: the committed small campaign and a writable copy of it."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from _campaign import SMALL_CAMPAIGN


@pytest.fixture
def small_campaign() -> Path:
    """The committed valid campaign (read only)."""
    return SMALL_CAMPAIGN


@pytest.fixture
def campaign(tmp_path: Path) -> Path:
    """A writable copy of the small campaign, to break in a test."""
    return Path(shutil.copytree(SMALL_CAMPAIGN, tmp_path / "campaign"))
