"""A base-driven response's units, from its ratio to the base below resonance
(jointcal.io._transmissibility): a response in m/s^2 under the g name (or g under the m/s^2 name) flagged at any
position of a campaign of any size, with one sentence naming the file, the run and the fix; no false positive on
the example's runs, the library's effects or a second mode at the band's bottom; 'undecided' or 'not checkable'
said in the run's row when the record cannot tell.

Each bad input is built from a clean run of the example campaign (raw_data/) or of a synthetic campaign, and
checked through `jointcal ingest CAMPAIGN RESULTS/ingest/runs.csv --on-data-problem flag` (the workflow's policy;
its ingest rule runs the same `ingest_campaign`), or, for the example's 24 positions of a response in m/s^2, through
`validate_run`, which `ingest_campaign` calls for each run alone."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.io import CampaignError, CampaignWarning, ingest_campaign, read_manifest, read_run, validate_run
from jointcal.io._amplitudes import low_frequency_ratio
from jointcal.units import G_SI  # m/s^2 per g
from tests._support.campaign import EXAMPLE, REPO, edit_run
from tests._support.ingest import FILE, OTHER, RUN, _flagged, _one_sentence, _scale


# ------------------------------------------------------------------------ the response's units, base-driven


@pytest.mark.parametrize("mistake, words", [
    ("m/s^2 named g", ["is it in m/s^2?", "name the column response_accel_m_s2 (it holds m/s^2)"]),
    ("g named m/s^2", ["read from 'response_accel_m_s2' as m/s^2", "is it in g?",
                       "name the column response_accel_g (it holds g)"]),
])
def test_a_base_driven_response_in_other_units_is_flagged(example, capsys, mistake, words):
    """Below resonance a base-driven response follows its base: 9.8 or 0.1 times it is a units mistake."""
    if mistake == "m/s^2 named g":
        edit_run(example, FILE, _scale("response_accel_g", G_SI))
    else:  # g values under the m/s^2 name (converted once more on read)
        edit_run(example, FILE, lambda d: d.rename(columns={"response_accel_g": "response_accel_m_s2"}))
    _flagged(example, capsys, RUN, "units:response_accel_g", f"{FILE}: below resonance (at 713 Hz", *words,
             f"or remove run '{RUN}' from manifest.csv")


def test_a_base_in_m_s2_beside_a_right_m_s2_response_converts_only_the_base(example, capsys):
    """The response, declared m/s^2 and in m/s^2, is right: the fix converts the base alone."""
    def edit(d: pd.DataFrame) -> pd.DataFrame:
        return pd.DataFrame({"time_s": d["time_s"], "base_accel_g": d["base_accel_g"] * G_SI,
                             "response_accel_m_s2": d["response_accel_g"] * G_SI})
    edit_run(example, FILE, edit)
    runs = _flagged(example, capsys, RUN, "level:base_accel_g", FILE, "is base_accel_g in m/s^2?",
                    "so the response's own unit is right", "export base_accel_g in g (divide by 9.80665)",
                    "leave the response as it is")
    assert "export base_accel_g and response_accel_g" not in capsys.readouterr().err
    assert runs.loc[OTHER, "flags"] == ""
    assert runs.loc[RUN, "response_units_check"].startswith("m/s^2 confirmed: response/base 0.102")


def test_both_channels_in_m_s2_are_converted_together(example):
    edit_run(example, FILE, lambda d: d.assign(base_accel_g=d["base_accel_g"] * G_SI,
                                               response_accel_g=d["response_accel_g"] * G_SI))
    with pytest.raises(CampaignError) as info:
        ingest_campaign(example)
    _one_sentence(str(info.value), FILE, "is the record in m/s^2?",
                  "export base_accel_g and response_accel_g in g (divide by 9.80665)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CampaignWarning)
        runs = ingest_campaign(example, on_data_problem="flag").set_index("run_id")
    assert runs.loc[RUN, "flags"] == "level:base_accel_g"
    assert runs.loc[RUN, "response_units_check"].startswith("flagged with the base: response/base 1 below")


# the issue-32 rig: the reassembly (beta 0.025, the most damped joint) swept fast (1000 Hz/s: eta_high), so at
# 10 g its response peaks at the band's top; levels in the test order 1, 10, 5, ... g, up and down in turn
FAST_SERIES = [{"level_g": lv, "directions": [d]} for lv, d in zip((1.0, 10.0, 5.0), ("up", "up", "down"))]
REASSEMBLY = {"Fs": 274.0, "KT": 0.90e6, "chi": -0.61, "beta": 0.025, "k": 8.56e5, "zeta_v": 0.0017}


@pytest.fixture(scope="module")
def fast_campaigns(tmp_path_factory) -> dict[int, Path]:
    """Base-driven synthetic campaigns of 2 and 3 runs (`FAST_SERIES`), made once (read only)."""
    from jointcal.synth import generate

    out = {}
    for n in (2, 3):
        folder = tmp_path_factory.mktemp(f"fast{n}")
        spec = {"seed": 11 + n, "sweep": {"rate_hz_per_s": 1000.0}, "series": FAST_SERIES[:n],
                "assemblies": {"reassembly": REASSEMBLY}}
        generate(spec, folder / "c", folder / "truth.json")
        out[n] = folder / "c"
    return out


# the response-units check is per run: `ingest_campaign` validates each run's record alone (`validate_run`, whose
# `level_problems` compares the response with its own base) and compares no run with another, so a run's position
# in its campaign decides nothing. The whole ingest is run where a bug of the campaign's loop would show (the
# first, second, middle and last of the example's 24 runs; every run of the 2- and 3-run campaigns); every one of
# the example's 24 positions is checked through `validate_run` itself, the function the ingest calls for each run,
# against the clean campaign's rows made once (`example_runs`).
END_TO_END = [(2, 0), (2, 1), (3, 0), (3, 1), (3, 2), (24, 0), (24, 1), (24, 12), (24, 23)]
M_S2_WORDS = ("the response read from 'response_accel_g' as g is", "is it in m/s^2?",
              "name the column response_accel_m_s2 (it holds m/s^2) or export it in g")


def _m_s2_under_the_g_name(src: Path, campaign: Path, row) -> None:
    """Copy run `row`'s file from campaign `src` into `campaign` with its response x9.80665 (m/s^2 under the g name)."""
    import shutil

    (campaign / row["file"]).parent.mkdir(parents=True, exist_ok=True)
    shutil.copy(src / row["file"], campaign / row["file"])
    edit_run(campaign, row["file"], _scale("response_accel_g", G_SI))


@pytest.fixture(scope="module")
def example_runs() -> list[tuple[pd.Series, dict]]:
    """The example campaign's 24 runs in manifest order: each manifest row and what `ingest_campaign` (whole, warnings
    raised) says of it, the clean campaign made once (read only)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        runs = ingest_campaign(EXAMPLE)
    rows = [row for _, row in read_manifest(EXAMPLE / "manifest.csv").iterrows()]
    assert len(rows) == len(runs) == 24 and list(runs["run_id"]) == [r["run_id"] for r in rows]
    return list(zip(rows, runs.to_dict("records")))


@pytest.mark.parametrize("n, position", END_TO_END)
def test_a_response_in_m_s2_under_the_g_name_is_flagged_in_a_campaign_of_any_size(tmp_path, fast_campaigns, capsys,
                                                                                   request, n, position):
    """One run's response exported in m/s^2 under the g name (x9.80665), at the first, second, middle or last
    position of the example's 24 runs or at each of a campaign of 2 or 3 (synthetic, the issue's fast-swept damped
    joint, whose 10 g response peaks at the band's top), through the whole `jointcal ingest`: that run alone is
    flagged with one sentence naming its file, the run and the fix; every other run's row says its g was confirmed
    (on the example: word for word the row it has in the clean campaign)."""
    import shutil

    src = EXAMPLE if n == 24 else fast_campaigns[n]
    campaign = Path(shutil.copytree(src, tmp_path / "c", ignore=shutil.ignore_patterns("*.yaml", "README.md")))
    row = read_manifest(campaign / "manifest.csv").iloc[position]
    assert len(read_manifest(campaign / "manifest.csv")) == n
    _m_s2_under_the_g_name(src, campaign, row)
    runs = _flagged(campaign, capsys, row["run_id"], "units:response_accel_g", f"{row['file']}: below resonance",
                    *M_S2_WORDS, f"or remove run '{row['run_id']}' from manifest.csv")
    assert runs.loc[row["run_id"], "response_units_check"].startswith("flagged: response/base")
    assert runs.drop(index=row["run_id"])["response_units_check"].str.startswith("g confirmed").all()
    if n == 24:
        clean = {c["run_id"]: c["response_units_check"] for _, c in request.getfixturevalue("example_runs")
                 if c["run_id"] != row["run_id"]}
        assert runs.drop(index=row["run_id"])["response_units_check"].to_dict() == clean


@pytest.mark.parametrize("position", range(24))
def test_a_response_in_m_s2_under_the_g_name_is_flagged_at_each_position_of_the_example(tmp_path, example_runs,
                                                                                        position):
    """Each of the example's 24 runs with its response in m/s^2 under the g name, read and validated as
    `ingest_campaign` reads and validates each run: flagged alone with one sentence naming its file, the run and the
    fix; every other run is the clean campaign's, clean and g confirmed. The record is scaled in memory (x9.80665, as
    above but without the gzip CSV rewrite, 0.65 s a run, whose 9 digits change nothing the check reads)."""
    row, _ = example_runs[position]
    path = tmp_path / "c" / row["file"]  # where the whole ingest above reads it: the message names it
    df = read_run(EXAMPLE / row["file"], row)
    df["response_accel_g"] = df["response_accel_g"] * G_SI
    with pytest.warns(CampaignWarning) as record:
        checks = validate_run(df, row, path, on_data_problem="flag")
    warned = [str(w.message) for w in record if issubclass(w.category, CampaignWarning)]
    assert len(warned) == 1, warned
    _one_sentence(warned[0], f"{row['file']}: below resonance", *M_S2_WORDS,
                  f"or remove run '{row['run_id']}' from manifest.csv")
    assert checks["flags"] == ["units:response_accel_g"]
    assert checks["response_units_check"].startswith("flagged: response/base")
    others = [c for i, (_, c) in enumerate(example_runs) if i != position]
    assert len(others) == 23 and all(c["flags"] == "" for c in others)
    assert all(c["response_units_check"].startswith("g confirmed") for c in others)


def test_the_issue_campaign_is_read_from_the_ratio_below_a_resonance_above_the_band(fast_campaigns):
    """The 2-run campaign's 10 g run peaks at the band's last window: the resonance is at or above 2.5 kHz, so the
    ratio at 741 Hz holds one mode's rise of at most 1/(1 - (741/2496)^2) = 1.097: the response's scale lies in
    [ratio / 1.097, ratio], which holds 1 (g) within 2 % (the example's spread) where m/s^2 would give 9.8."""
    from jointcal.io._transmissibility import response_ratio

    row = read_manifest(fast_campaigns[2] / "manifest.csv").iloc[1]
    df = read_run(fast_campaigns[2] / row["file"], row)
    low = response_ratio(df["base_accel_g"].to_numpy(), df["response_accel_g"].to_numpy(), row["sample_rate_hz"],
                         row["f_start_hz"], row["f_stop_hz"], row["sweep_rate_hz_per_s"])
    assert low.beyond and low.f_peak > 0.99 * row["f_stop_hz"]
    assert low.rise == pytest.approx(1 / (1 - (low.f_low / low.f_peak) ** 2)) and low.rise < 1.1
    assert low.ratio / low.rise <= 1.02 and low.ratio >= 0.98
    assert low.ratio / low.rise <= low.scale <= low.ratio


def test_a_run_whose_record_cannot_tell_its_response_units_says_so_in_its_row(tmp_path, voltage):
    """A band that starts at 0.9 of the resonance (2000-2500 Hz around 2.26 kHz): no quasi-static ratio, so the
    row says 'undecided' and why; a voltage-driven run: 'not checkable'."""
    from jointcal.synth import generate

    spec = {"seed": 21, "sweep": {"f_start_hz": 2000.0, "f_stop_hz": 2500.0, "rate_hz_per_s": 300.0},
            "series": [{"level_g": 1.0, "directions": ["up"]}],
            "assemblies": {"first": {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5,
                                     "zeta_v": 0.0015}}}
    generate(spec, tmp_path / "near", tmp_path / "truth.json")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        near = ingest_campaign(tmp_path / "near")
        volt = ingest_campaign(voltage)
    assert near.loc[0, "flags"] == ""
    assert near.loc[0, "response_units_check"].startswith("undecided: the band starts at 0.")
    assert "of the resonance" in near.loc[0, "response_units_check"]
    assert volt["response_units_check"].str.startswith("not checkable: a voltage-driven record").all()


def test_units_check_has_no_false_positive_on_the_example_runs(example_runs):
    """All 24 runs: the response/base ratio at the band's bottom, over a single mode's rise, is 1 within 2%; the whole
    ingest (`example_runs`, warnings raised) flags none and confirms g for each."""
    man = read_manifest(REPO / "raw_data" / "manifest.csv")
    for row in man.to_dict("records"):
        df = read_run(REPO / "raw_data" / row["file"], row)
        f_low, ratio, f_peak = low_frequency_ratio(df["base_accel_g"].to_numpy(), df["response_accel_g"].to_numpy(),
                                                   row["sample_rate_hz"], row["f_start_hz"], row["f_stop_hz"],
                                                   row["sweep_rate_hz_per_s"])
        assert ratio * (1 - (f_low / f_peak) ** 2) == pytest.approx(1.0, abs=0.02), row["run_id"]
    runs = pd.DataFrame([checks for _, checks in example_runs])
    assert len(runs) == 24
    assert (runs["flags"] == "").all() and runs["response_units_check"].str.startswith("g confirmed").all()


EFFECT_CASES = [(e, {}) for e in ("none", "fixture_flexibility", "channel_delay", "cubic_stiffening",
                                  "joint_settling", "quadratic_damping", "sensor_gain", "contact_spring")]
EFFECT_CASES.append(("fixture_flexibility", {"m_can_ratio": 2.0, "f_can_hz": 3200.0}))  # a soft fixture


@pytest.mark.parametrize("effect, params", EFFECT_CASES)
def test_units_check_has_no_false_positive_on_synthetic_campaigns(tmp_path, effect, params):
    """`jointcal synth` with each library effect (1 g up, 10 g down): no flag. A sensor gain (1.25) is not a
    unit; a flexible fixture raises the ratio below resonance (here 1.21 where a rigid one gives 1.11)."""
    from jointcal.synth import generate

    spec = {"seed": 3, "file_format": "mat", "sweep": {"rate_hz_per_s": 1000.0},
            "series": [{"level_g": 1.0, "directions": ["up"]}, {"level_g": 10.0, "directions": ["down"]}],
            "assemblies": {"first": {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5,
                                     "zeta_v": 0.0015}},
            "effect": {"name": effect, "params": params}}
    generate(spec, tmp_path / "c", tmp_path / "truth.json")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert (ingest_campaign(tmp_path / "c")["flags"] == "").all()
    if params:
        row = read_manifest(tmp_path / "c" / "manifest.csv").iloc[0]
        df = read_run(tmp_path / "c" / row["file"], row)
        low = low_frequency_ratio(df["base_accel_g"].to_numpy(), df["response_accel_g"].to_numpy(), 12800.0,
                                  row["f_start_hz"], row["f_stop_hz"], row["sweep_rate_hz_per_s"])
        assert low[1] > 1.18  # by physics, not by units


def test_units_check_says_nothing_when_another_mode_sits_at_the_band_bottom():
    """A second mode at 745 Hz (participation 0.5) lifts the response/base ratio at the 700 Hz band bottom to
    7.5 times a single mode's rise, inside the m/s^2 band: the ratio does not follow one mode over the first
    quarter of the way to the 2.2 kHz peak, so nothing is named (exact linear responses, scipy.signal.lsim)."""
    from scipy import signal

    from tests._support.lti import lsim

    fs, f0, f1, rate = 12800.0, 700.0, 2600.0, 1000.0
    t = np.arange(int(((f1 - f0) / rate + 0.05) * fs)) / fs
    tt = np.minimum(t, (f1 - f0) / rate)
    base = np.sin(2 * np.pi * (f0 * tt + 0.5 * rate * tt**2)) * (t < (f1 - f0) / rate)

    def relative_accel(fn: float, zeta: float) -> np.ndarray:  # z'' of z'' + 2 zeta w z' + w^2 z = -a_base
        w = 2 * np.pi * fn
        sdof = signal.StateSpace([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [-1.0]], [[-w * w, -2 * zeta * w]],
                                 [[0.0]])
        return lsim(sdof, base, t) - base

    resp = base + relative_accel(2200.0, 0.02) + 0.5 * relative_accel(745.0, 0.02)
    assert low_frequency_ratio(base, resp, fs, f0, f1, rate) is None
    row = {"run_id": "r", "assembly": "a", "sequence": 1, "level_g": 1.0, "direction": "up", "f_start_hz": f0,
           "f_stop_hz": f1, "sweep_rate_hz_per_s": rate, "sample_rate_hz": fs, "file": "r.csv"}
    df = pd.DataFrame({"time_s": t, "base_accel_g": base, "response_accel_g": resp})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert validate_run(df, row, "r.csv")["flags"] == []


def test_a_voltage_driven_response_in_other_units_cannot_be_seen_and_the_contract_says_so(voltage):
    """Nothing in a voltage-driven record fixes the response's scale: x9.81 passes unflagged, and the
    contract docs say so with the user's own check."""
    edit_run(voltage, read_manifest(voltage / "manifest.csv")["file"].iloc[0], _scale("response_accel_g", G_SI))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert (ingest_campaign(voltage)["flags"] == "").all()
    for doc in (REPO / "README.md", REPO / "raw_data" / "README.md"):
        text = " ".join(doc.read_text().split())
        assert "cannot be checked" in text and "response units on a voltage- or force-driven run" in text, doc
