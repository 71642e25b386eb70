"""Shared fixtures: the committed small campaign and a writable copy of it."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from _campaign import SMALL_CAMPAIGN, voltage_campaign


@pytest.fixture
def small_campaign() -> Path:
    """The committed valid campaign (read only)."""
    return SMALL_CAMPAIGN


@pytest.fixture
def campaign(tmp_path: Path) -> Path:
    """A writable copy of the small campaign, to break in a test."""
    return Path(shutil.copytree(SMALL_CAMPAIGN, tmp_path / "campaign"))


@pytest.fixture(scope="session")
def voltage_source(tmp_path_factory) -> Path:
    """A synthetic voltage-driven campaign, made once per session (read only)."""
    return voltage_campaign(tmp_path_factory.mktemp("voltage") / "campaign")


@pytest.fixture
def voltage(tmp_path: Path, voltage_source: Path) -> Path:
    """A writable copy of the synthetic voltage-driven campaign, to break in a test."""
    return Path(shutil.copytree(voltage_source, tmp_path / "voltage"))
