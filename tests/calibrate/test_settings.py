"""The ``calibrate:`` config section (jointcal.calibrate.settings): the workflow's
config.yaml gives the Python defaults."""
from __future__ import annotations

import pytest
import yaml

from jointcal.calibrate import CalibrateSettings
from tests._support.campaign import REPO


def test_config_snippet_equals_the_python_defaults():
    keys = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())
    # the one difference: the workflow takes the model kind from the campaign (auto), the API defaults to the paper's
    assert CalibrateSettings.from_config(keys["calibrate"]) == CalibrateSettings(model_kind="auto")
    with pytest.raises(ValueError, match="unknown key"):
        CalibrateSettings.from_config({"populaton": 10})
