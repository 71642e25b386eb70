"""The ``posterior:`` config section (jointcal.posterior.settings): the workflow's
config.yaml gives the Python defaults."""
from __future__ import annotations

import pytest
import yaml

from jointcal.posterior import PosteriorSettings
from tests._support.campaign import REPO


def test_settings_snippet_equals_the_python_defaults():
    keys = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    assert PosteriorSettings.from_config(keys["posterior"]) == PosteriorSettings()
    with pytest.raises(ValueError, match="n_walkers"):
        PosteriorSettings.from_config({"n_walkers": 10})
