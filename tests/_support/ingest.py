"""Test helpers (not jointcal code): runs of a campaign broken the way labs break them, and
what ingest says about them."""
from __future__ import annotations

import warnings
from pathlib import Path

import pandas as pd
import pytest

from jointcal.cli import main
from jointcal.io import CampaignError, CampaignWarning, ingest_campaign
from jointcal.units import G_SI  # m/s^2 per g


def _si(d: pd.DataFrame) -> None:
    d[["base_accel_g", "response_accel_g"]] *= G_SI


def _set(col, value):
    def edit(d):
        d[col] = value
    return edit


RUN, OTHER = "first_01_1g_up", "first_07_2g_up"  # a 1 g up sweep and a 2 g one, from raw_data/
FILE = f"runs/{RUN}.csv.gz"


def _scale(col: str, factor: float):
    def edit(d: pd.DataFrame) -> None:
        d[col] = d[col] * factor
    return edit


def _one_sentence(msg: str, *words: str) -> None:
    assert all(w in msg for w in words), msg
    assert "\n" not in msg and msg.endswith((".", "?")), msg


def _flag(campaign: Path, rid: str, *words: str) -> list[str]:
    """Ingest under 'flag': the run's flags; under 'error': one sentence naming the words."""
    with pytest.warns(CampaignWarning) as record:
        runs = ingest_campaign(campaign, on_data_problem="flag").set_index("run_id")
    msgs = [str(w.message) for w in record if issubclass(w.category, CampaignWarning)]
    assert any(all(w in m for w in words) for m in msgs), msgs
    with pytest.raises(CampaignError) as info:
        ingest_campaign(campaign)
    _one_sentence(str(info.value), *words)
    return runs.loc[rid, "flags"].split(";")


def _raises(campaign: Path, *words: str) -> str:
    with pytest.raises(CampaignError) as info:
        ingest_campaign(campaign, on_data_problem="flag")
    _one_sentence(str(info.value), *words)
    return str(info.value)


def _ingest(campaign: Path, capsys) -> tuple[int, str, pd.DataFrame | None]:
    """Exit status, stderr and runs.csv (None when not written) of `jointcal ingest` into a results folder."""
    out = campaign.parent / "results" / "ingest" / "runs.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CampaignWarning)  # the CLI prints them
        code = main(["ingest", str(campaign), str(out), "--on-data-problem", "flag"])
    err = capsys.readouterr().err
    return code, err, (pd.read_csv(out, keep_default_na=False).set_index("run_id") if out.exists() else None)


def _flagged(campaign: Path, capsys, rid: str, flag: str, *words: str) -> pd.DataFrame:
    """The run gets `flag` and a warning naming `words`; the other runs are clean; runs.csv is written."""
    code, err, runs = _ingest(campaign, capsys)
    assert code == 0 and runs is not None, err
    warned = [line.removeprefix("jointcal: warning: ") for line in err.splitlines() if "warning" in line]
    assert len(warned) == 1, err
    _one_sentence(warned[0], *words)
    assert runs.loc[rid, "flags"].split(";") == [flag]
    assert (runs.drop(index=rid)["flags"] == "").all()
    return runs


def _stopped(campaign: Path, capsys, *words: str) -> str:
    """Ingest stops with one sentence naming `words`; no runs.csv is left."""
    code, err, runs = _ingest(campaign, capsys)
    lines = err.strip().splitlines()
    assert code == 2 and runs is None, err
    assert len(lines) == 1 and lines[0].startswith("jointcal: ") and "Traceback" not in err, err
    _one_sentence(lines[0], *words)
    return lines[0]


def _write_csv(path, cols: dict) -> None:
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.12g")
