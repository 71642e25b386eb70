"""Test helpers (not jointcal code): where the small campaign lives and how to break a copy."""
from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from jointcal.io import read_run

DATA = Path(__file__).parents[1] / "data"
SMALL_CAMPAIGN = DATA / "small_campaign"
REPO = Path(__file__).parents[2]
EXAMPLE = REPO / "raw_data"
# the default generator (no hidden effect) with the seed the session's default campaign is made with (conftest.py)
DEFAULT_SPEC = {"seed": 7}
# a 1 lbf, 100 Hz linear beam on an open-loop shaker, only the amplifier voltage recorded (tests/synth/test_shaker.py)
BEAM = {"k": 1022.0, "zeta_v": 0.015, "weight_lbf": 1.0}
SHAKER = {"armature_weight_lbf": 0.05, "suspension_hz": 15.0, "bl_lbf_per_A": 0.5, "coil_ohm": 2.0, "coil_mH": 0.3}
VOLTAGE_SPEC = {"seed": 8, "sample_rate_hz": 1024.0,
                "sweep": {"f_start_hz": 60.0, "f_stop_hz": 140.0, "rate_hz_per_s": 5.0, "tail_s": 1.0},
                "series": [{"level_V": 0.3, "directions": ["up", "down"]}], "assemblies": {"beam": BEAM},
                "rig": {"reference": "voltage", "shaker": SHAKER}}


def example_copy(folder: Path, *run_ids: str) -> Path:
    """A copy of the example campaign (raw_data/) holding only `run_ids` (every run when none), to break."""
    manifest = pd.read_csv(EXAMPLE / "manifest.csv", dtype=str, keep_default_na=False)
    if run_ids:
        manifest = manifest[manifest["run_id"].isin(run_ids)]
    for file in manifest["file"]:
        (folder / file).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(EXAMPLE / file, folder / file)
    manifest.to_csv(folder / "manifest.csv", index=False)
    return folder


def voltage_campaign(folder: Path) -> Path:
    """A synthetic voltage-driven campaign (`jointcal synth` of VOLTAGE_SPEC): the beam, up and down at 0.3 V."""
    from jointcal.synth import generate

    generate(VOLTAGE_SPEC, folder, folder.parent / f"{folder.name}_truth.json")
    return folder


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


def unit(results: Path, assembly: str) -> str:
    """The mode of an assembly that holds one (its folder under each per-unit stage: ``<stage>/<assembly>/<mode>``)."""
    from jointcal._workflow import modal_units

    modes = [m for a, m in modal_units(results / "modal" / "modal_properties.csv") if a == assembly]
    assert len(modes) == 1, modes
    return modes[0]


def modal_tables(folder: Path) -> Path:
    """The modal stage's three tables of the virtual campaign in folder/campaign (sweeps through their envelopes,
    dwells and ring-downs from their records), written in folder/modal, as the workflow's modal rule writes them;
    returns folder/modal."""
    from jointcal.io import ingest_campaign, test_kind, write_csv_atomic
    from jointcal.measure.campaign import campaign_modal
    from jointcal.measure.envelopes import envelopes, meta_dict
    from jointcal.measure.scatter import scatter
    from jointcal.measure.testkinds.read import backbone_table

    runs = ingest_campaign(folder / "campaign")

    def load(row):
        record = read_run(folder / "campaign" / row["file"], row)
        if test_kind(row) != "sweep":
            return None, {}, record
        env, meta = envelopes(record, row)
        return env, {**meta_dict(meta), "error": ""}, record

    points: list = []
    rows, _, _ = campaign_modal(runs, load, {}, points=points)
    table = pd.DataFrame(rows)
    modal = folder / "modal"
    write_csv_atomic(table, modal / "modal_properties.csv")
    write_csv_atomic(scatter(table), modal / "scatter.csv")
    write_csv_atomic(backbone_table(table, points), modal / "backbone.csv")
    return modal
