"""The workflow's modal stage on campaigns other than the example: bad runs inside a valid
campaign flagged while the rest finish, a voltage-driven chirp campaign, lab exports read as their CSV."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.io import read_manifest, read_run, write_run
from jointcal.synth import generate
from tests._support.campaign import edit_manifest
from tests.io.test_lab_formats import NAMES, WRITERS


FIRST = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}


def _merge_run(dst: Path, src: Path, run_id: str, new_id: str, sequence: int) -> None:
    """Copy one run of campaign src into campaign dst under a new id."""
    ms, md = pd.read_csv(src / "manifest.csv"), pd.read_csv(dst / "manifest.csv")
    row = ms[ms.run_id == run_id].iloc[0].copy()
    target = dst / "runs" / f"{new_id}.csv.gz"
    target.write_bytes((src / row["file"]).read_bytes())
    row["run_id"], row["file"], row["sequence"] = new_id, f"runs/{new_id}.csv.gz", sequence
    pd.concat([md, row.to_frame().T]).to_csv(dst / "manifest.csv", index=False)


@pytest.mark.slow
def test_bad_runs_inside_a_valid_campaign_are_flagged_and_the_rest_finish(tmp_path, workdir):
    """Workflow: a band that misses the resonance, a clipped response, a NaN burst."""
    from tests._support.workflow import snakemake

    base = {"seed": 9, "sweep": {"f_start_hz": 1500.0, "f_stop_hz": 2700.0, "rate_hz_per_s": 400.0},
            "series": [{"level_g": 1.0, "directions": ["up", "down"]}], "assemblies": {"first": FIRST}}
    generate(base, tmp_path / "c", tmp_path / "t.json")
    up = [{"level_g": 1.0, "directions": ["up"]}]  # the two donors' up runs only: byte-identical to the first run
    generate({**base, "series": up, "sweep": {"f_start_hz": 700.0, "f_stop_hz": 1500.0, "rate_hz_per_s": 400.0}},
             tmp_path / "low", tmp_path / "t2.json")  # of the up-and-down campaign (checked), and only it is merged
    generate({**base, "series": up, "measurement": {"full_scale_g": {"base": "auto", "response": 10.0}}},
             tmp_path / "clip", tmp_path / "t3.json")
    _merge_run(tmp_path / "c", tmp_path / "low", "first_01_1g_up", "low_band", 3)
    _merge_run(tmp_path / "c", tmp_path / "clip", "first_01_1g_up", "clipped", 4)
    from jointcal.io import read_run
    nanfile = tmp_path / "c" / "runs" / "first_02_1g_down.csv.gz"
    df = read_run(nanfile)
    df.loc[30000:30200, "response_accel_g"] = np.nan
    write_run(nanfile, df["time_s"], df["base_accel_g"], df["response_accel_g"])
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "modal", "--config", f"raw_data={tmp_path / 'c'}", f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    t = pd.read_csv(out / "modal" / "modal_properties.csv", dtype={"flags": str}).set_index("run_id")
    t["flags"] = t["flags"].fillna("")
    assert "unusable" in t.loc["low_band", "flags"] and "resonance_outside_band" in t.loc["low_band", "flags"]
    assert "clipped:response_accel_g" in t.loc["clipped", "flags"]
    assert "nonfinite:response_accel_g" in t.loc["first_02_1g_down", "flags"]
    assert "bad_samples" in t.loc["first_02_1g_down", "flags"]
    assert t.loc["first_01_1g_up", "flags"] == ""
    assert abs(t.loc["first_02_1g_down", "f_res_hz"] / t.loc["first_01_1g_up", "f_res_hz"] - 1) < 5e-4
    log = (out / "logs" / "modal.log").read_text()
    for rid in ("low_band", "clipped", "first_02_1g_down"):
        assert f"warning: {rid}:" in log and f"warning: {rid}:" in res.stderr
    assert (out / "figures" / "fig3_6_frequency_damping.png").is_file()


BEAM = {"k": 1022.0, "zeta_v": 0.015, "weight_lbf": 1.0}  # 100 Hz, zeta 1.5%, linear
SHAKER = {"armature_weight_lbf": 0.05, "suspension_hz": 15.0, "bl_lbf_per_A": 0.5, "coil_ohm": 2.0, "coil_mH": 0.3}


def _lab_copy(campaign: Path, lab: Path) -> Path:
    """A copy of a two-run voltage campaign with its first run exported as TDMS and its second as a Test.Lab struct,
    the manifest naming each channel as the lab does."""
    import shutil

    lab = Path(shutil.copytree(campaign, lab))
    man = read_manifest(lab / "manifest.csv")
    for row, suffix in zip(man.to_dict("records"), (".tdms", ".mat")):
        df = read_run(lab / row["file"], row)
        WRITERS[suffix](lab / row["file"].replace(".csv.gz", suffix), df, {"drive_V": "V", "response_accel_g": "g"})
        (lab / row["file"]).unlink()
    edit_manifest(lab, lambda m: m.assign(file=[f.replace(".csv.gz", s) for f, s in zip(m["file"], (".tdms", ".mat"))],
                                          reference_channel=NAMES["drive_V"], response_channel=NAMES["response_accel_g"]))
    return lab


@pytest.mark.slow
def test_workflow_reads_a_voltage_driven_chirp_campaign_and_its_lab_exports_as_the_csv(tmp_path, workdir):
    """Workflow 'modal_properties' on a voltage-driven beam campaign (eta-20 chirps, up and down):
    ingest takes level_V / drive_V, the modal stage reads the rig's pole (swept-mode fit; pair backbone
    and FRF fit beside it), each
    run's FRF is written. The same campaign with one run as TDMS and the other as a Test.Lab struct: the workflow's
    modal table is the CSV campaign's (every stage reads the record with its manifest row). One test, so that the
    CSV campaign's workflow run is made once for both checks."""
    import pandas as pd
    from tests._support.workflow import snakemake, workflow_copy

    spec = {"seed": 8, "sample_rate_hz": 1024.0, "sweep": {"f_start_hz": 70.0, "f_stop_hz": 130.0,
                                                           "rate_hz_per_s": 20.0 * (97.66 * 0.0192) ** 2,
                                                           "tail_s": 1.0},
            "series": [{"level_V": 1.0, "directions": ["up", "down"]}], "assemblies": {"beam": BEAM},
            "rig": {"reference": "voltage", "shaker": SHAKER}}
    generate(spec, tmp_path / "c", tmp_path / "t.json")
    truth = json.loads((tmp_path / "t.json").read_text())["runs"]
    out = tmp_path / "results"
    res = snakemake(workdir, "--cores", "2", "modal_properties", "--config", f"raw_data={tmp_path / 'c'}",
                    f"results={out}")
    assert res.returncode == 0, res.stderr[-3000:]
    t = pd.read_csv(out / "modal" / "modal_properties.csv", dtype={"flags": str})
    assert (t["f_res_method"] == "sweep_fit").all() and "level_V" in t.columns
    for r, tr in zip(t.to_dict("records"), truth):
        assert r["f_res_hz"] == pytest.approx(tr["f_rig_hz"], rel=2e-3)
        assert r["zeta_frf"] == pytest.approx(tr["zeta_rig"], rel=0.05)
        assert r["zeta_backbone"] == pytest.approx(tr["zeta_rig"], rel=0.05)
        assert r["zeta_sweep"] == pytest.approx(tr["zeta_rig"], rel=0.05)
        frf = pd.read_csv(out / "modal" / "frf" / f"{r['run_id']}.csv")
        assert {"h1_re", "h2_re", "coherence", "fit_re"} <= set(frf.columns)
    lab = _lab_copy(tmp_path / "c", tmp_path / "lab")
    (tmp_path / "wf_lab").mkdir()
    res = snakemake(workflow_copy(tmp_path / "wf_lab"), "--cores", "2", "modal_properties", "--config",
                    f"raw_data={lab}", f"results={tmp_path / 'results_lab'}")
    assert res.returncode == 0, res.stderr[-3000:]
    tables = {name: pd.read_csv(folder / "modal" / "modal_properties.csv", keep_default_na=False)
              for name, folder in (("csv", out), ("lab", tmp_path / "results_lab"))}
    assert (tables["lab"]["f_res_method"] == "sweep_fit").all()
    pd.testing.assert_frame_equal(tables["lab"], tables["csv"])
