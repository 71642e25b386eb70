"""The modes of a campaign: found in each run's FRF, tracked across runs, each run read at the modes its
band holds (jointcal.measure.modes, jointcal.measure.campaign).

Truths: closed-form FRFs of linear modes (the peaks), and a virtual structure with two amplitude-dependent modes
integrated by the exact Iwan simulator (tests/_support/two_modes.py), force-driven (read-outs held against each
mode's first-harmonic balance at the amplitude the run reached) and voltage-driven through an open-loop shaker
that couples the two jointed modes (against the coupled rig's pole of each mode at the amplitude it reached at
the driving point).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from jointcal._workflow import modal_units
from jointcal.io import read_manifest, read_run
from jointcal.measure.campaign import campaign_modal
from jointcal.measure.envelopes import envelopes
from jointcal.measure.modes import modal_peaks, mode_name, track_modes
from tests._support.two_modes import campaign, truth


def _receptance(f, modes):
    w = 2 * np.pi * f
    return sum(1.0 / (wn**2 - w**2 + 2j * z * wn * w) for wn, z in ((2 * np.pi * fn, z) for fn, z in modes))


def test_peaks_of_two_linear_modes_and_not_of_noise():
    f = np.arange(1.0, 400.0, 0.05)
    X = _receptance(f, [(18.6, 0.02), (95.0, 0.01)])
    rng = np.random.default_rng(3)
    coherence = np.ones_like(f)
    ripple = np.convolve(rng.standard_normal(f.size + 3), np.ones(4) / 2, "valid")  # zero-padded: 4 lines a bin
    noisy = X * (1 + 0.1 * ripple)  # 10% ripple of 20-line peaks (2x over 3 lines): no mode of its own
    coherence[f < 6] = 0.3  # noise over w^2 at the band's low end: not the drive's
    found = modal_peaks(f, noisy, coherence, (0.5, 400.0))
    # highest first, each within a quarter of its half-power band (2 zeta f): where the mode's fit starts
    assert found.size == 2 and abs(found[0] - 18.6) < 0.5 * 0.02 * 18.6 and abs(found[1] - 95.0) < 0.5 * 0.01 * 95
    # a mode at the band's edge is the band's, and a mode the drive does not reach is not read
    assert modal_peaks(f, X, np.ones_like(f), (20.0, 95.5)).size == 0
    assert list(np.round(modal_peaks(f, X, np.where(f > 50, 0.2, 1.0), (0.5, 400.0)))) == [19]


def test_tracking_names_each_mode_by_its_low_level_frequency_and_reads_each_run_whose_band_holds_it():
    peaks = {"w1": [18.7, 95.2], "w2": [18.4, 94.1], "u1": [95.3], "u2": [], "n1": [18.6]}
    bands = {"w1": (0.5, 110), "w2": (0.5, 110), "u1": (70, 110), "u2": (70, 110), "n1": (5, 40)}
    levels = {"w1": 0.05, "w2": 0.3, "u1": 0.05, "u2": 0.3, "n1": 0.1}
    t = track_modes(peaks, bands, levels)
    assert sorted(t["mode"].unique()) == ["m18", "m95"]
    assert set(t.loc[t["mode"] == "m18", "run_id"]) == {"w1", "w2", "n1"}  # u1, u2 do not hold it
    m95 = t[t["mode"] == "m95"].set_index("run_id")
    assert set(m95.index) == {"w1", "w2", "u1", "u2"}
    assert not m95.loc["u2", "detected"] and m95.loc["u2", "f_guess_hz"] == pytest.approx(np.median([95.2, 94.1, 95.3]))
    only = track_modes(peaks, bands, levels, mode_hz=[96.0])
    assert set(only["mode"]) == {"m95"}
    assert mode_name(18.61) == "m18" and mode_name(95.0) == "m95"
    # a peak in one run of five that hold its frequency is noise, not a mode
    assert "m30" not in set(track_modes({**peaks, "w1": [18.7, 30.2, 95.2]}, bands, levels)["mode"])


def _read_campaign(folder):
    man = read_manifest(folder / "manifest.csv").assign(flags="")

    def load(row):
        rec = read_run(folder / row["file"], row)
        env, meta = envelopes(rec, row)
        return env, {"rate_hz_per_s": meta.rate_hz_per_s, "window_s": meta.window_s}, rec

    rows, frf, _ = campaign_modal(man, load, {})
    table = pd.DataFrame(rows)
    table.insert(2, "mode", table.pop("mode"))
    table.to_csv(folder / "modal_properties.csv", index=False)
    return folder, table, frf


@pytest.fixture(scope="module")
def two_modes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two_modes")
    campaign(folder, levels=(0.04, 0.32))
    return _read_campaign(folder)


@pytest.mark.slow
def test_two_amplitude_dependent_modes_each_read_at_its_own_backbone(two_modes):
    folder, table, frf = two_modes
    assert sorted(table["mode"].unique()) == ["m227", "m99"]
    low, high = table[table["mode"] == "m99"], table[table["mode"] == "m227"]
    assert set(low["run_id"]) == {"wide_0.04lbf", "wide_0.32lbf"}  # the upper family's band lacks it
    assert len(high) == 4 and (table["f_res_method"] == "sweep_fit").all()
    for mode, g in (("low", low), ("high", high)):
        f_t, z_t = truth(mode, g["q_in"].to_numpy())
        assert np.abs(g["f_res_hz"] / f_t - 1).max() < 0.0005, (mode, g["f_res_hz"].to_numpy(), f_t)
        assert np.abs(g["zeta_res"] / z_t - 1).max() < 0.05, (mode, g["zeta_res"].to_numpy(), z_t)
    # the upper mode's backbone is the same whichever family reads it: each family's points on the truth,
    # and the two families' (q, f) on one curve through the softening
    for fam in ("wide", "upper"):
        g = high[high["run_id"].str.startswith(fam)]
        assert np.abs(g["f_res_hz"] / truth("high", g["q_in"].to_numpy())[0] - 1).max() < 0.0003
    assert table.groupby("mode")["f_res_hz"].agg(lambda f: f.max() / f.min() - 1).min() > 0.015  # softens
    # the FRF file holds one fit per mode read
    assert set(frf["wide_0.32lbf"]["mode"]) == {"m99", "m227"}
    assert modal_units(folder / "modal_properties.csv") == [("beam", "m99"), ("beam", "m227")]


@pytest.mark.slow
def test_two_jointed_modes_coupled_by_a_voltage_driven_shaker_each_read_at_its_rig_pole(tmp_path):
    """The two jointed modes of the force test on the open-loop shaker of tests/_support/rigs.py, driven by the
    amplifier's voltage (the coil's back-EMF and the armature couple them: one 5-state integration with a joint
    on each mode), 1% noise, the benchmark's campaign (two families, three levels 0.25-2 V). Each mode is read on
    the coupled rig's pole of that mode at its q_in (measured max 0.012% and 0.53%), q_in is the amplitude the
    mode reached at the driving point (measured within 1.2%), and the upper mode's backbone is the same from
    both families (measured: their mean offsets from the truth differ by 0.004%).

    Three levels, not two: one wide run of this noise realisation (the second) shows a noise peak at the
    driving point's antiresonance (175 Hz, between the modes), which tracking drops as one run of three that
    hold it but keeps as one of two."""
    man = campaign(tmp_path, ref="voltage").set_index("run_id")
    _, table, _ = _read_campaign(tmp_path)
    modes = sorted(table["mode"].unique(), key=lambda m: int(m[1:]))
    assert len(modes) == 2 and (table["f_res_method"] == "sweep_fit").all()
    low, high = table[table["mode"] == modes[0]], table[table["mode"] == modes[1]]
    assert set(low["run_id"]) == {"wide_0.25V", "wide_0.75V", "wide_2.00V"} and len(high) == 6
    err = {}
    for mode, g in (("low", low), ("high", high)):
        f_t, z_t = truth(mode, g["q_in"].to_numpy(), "voltage")
        err[mode] = g["f_res_hz"].to_numpy() / f_t - 1
        assert np.abs(err[mode]).max() < 5e-4, (mode, g["f_res_hz"].to_numpy(), f_t)
        assert np.abs(g["zeta_res"] / z_t - 1).max() < 0.05, (mode, g["zeta_res"].to_numpy(), z_t)
        q_reached = man.loc[g["run_id"], f"q_{mode}_in"].to_numpy()
        assert np.abs(g["q_in"].to_numpy() / q_reached - 1).max() < 0.03
        assert g["f_res_hz"].max() / g["f_res_hz"].min() - 1 > 0.015  # softens over the levels
        # the rig is not the structure: its pole lies well off the mode's own first-harmonic balance
        assert np.abs(truth(mode, g["q_in"].to_numpy())[0] / f_t - 1).min() > 10 * 5e-4
    fam = high["run_id"].str.startswith("upper").to_numpy()
    assert abs(err["high"][fam].mean() - err["high"][~fam].mean()) < 2e-4


@pytest.mark.slow
def test_a_voltage_driven_chirp_over_two_modes_reads_each(tmp_path):
    """The jointed beam of tests/_support/rigs.py on its open-loop shaker (the coil, the armature, a second, linear
    mode at 230 Hz), chirped over both modes at eta 50 with 2% noise: both modes found in every run; the
    jointed one on the coupled rig's pole at its q_in (0.1%, 5%), the linear one at one frequency and
    damping whatever the level."""
    from tests._support import rigs as _rigs

    from jointcal.synth import generate

    f, z = _rigs.truth_curve("voltage", _rigs.Q_TARGETS[1])
    spec = {"seed": 1, "sample_rate_hz": 2048.0, "measurement": {"noise_fraction": 0.02},
            "sweep": {"f_start_hz": 30.0, "f_stop_hz": 260.0, "rate_hz_per_s": 50 * (f * z) ** 2, "ramp_s": 0.05,
                      "tail_s": 1.5},
            "series": [{"level_V": v, "directions": ["up"]} for v in _rigs.levels_V()],
            "assemblies": {"beam": _rigs.JOINTED_BEAM},
            "rig": {"reference": "voltage", "shaker": _rigs.SMALL_SHAKER, "second_mode": _rigs.SECOND_MODE}}
    folder = tmp_path / "campaign"
    generate(spec, folder, tmp_path / "truth.json")
    man = read_manifest(folder / "manifest.csv").assign(flags="")

    def load(row):
        rec = read_run(folder / row["file"], row)
        env, meta = envelopes(rec, row)
        return env, {"rate_hz_per_s": meta.rate_hz_per_s}, rec

    t = pd.DataFrame(campaign_modal(man, load, {})[0])
    modes = sorted(t["mode"].unique(), key=lambda m: int(m[1:]))
    assert len(modes) == 2 and t.groupby("mode").size().to_dict() == {m: 3 for m in modes}
    jointed, linear = t[t["mode"] == modes[0]], t[t["mode"] == modes[1]]
    f_t, z_t = np.array([_rigs.truth_curve("voltage", q) for q in jointed["q_in"]]).T
    assert np.abs(jointed["f_res_hz"] / f_t - 1).max() < 1e-3 and np.abs(jointed["zeta_res"] / z_t - 1).max() < 0.05
    assert jointed["f_res_hz"].max() / jointed["f_res_hz"].min() - 1 > 0.01  # the joint softens over the levels
    assert linear["f_res_hz"].max() / linear["f_res_hz"].min() - 1 < 5e-4  # the linear mode does not
    assert linear["zeta_res"].max() / linear["zeta_res"].min() - 1 < 0.05


def test_a_voltage_coil_is_fitted_on_the_slowest_sweeps_and_held_where_most_of_them_ask_for_it(monkeypatch):
    """`assembly_coil` on a plan of four runs of one mode (two at the slowest rate): only the slowest are read with
    the coil fitted; their median is held when both ask for one, none when only one of the two does; the
    note names the runs."""
    import jointcal.measure.campaign as camp

    fits = {"a": (1000.0, 5e5), "b": (1100.0, 7e5), "c": (1.0, 1.0), "d": (1.0, 1.0)}
    calls = []

    def fake(env, row, *, coil, **kw):
        calls.append((row["run_id"], coil))
        w_e, g = fits[row["run_id"]]
        return {"coil_w_e_rad_s": w_e, "coil_g_per_s2": g} if np.isfinite(w_e) else {}

    monkeypatch.setattr(camp, "modal_properties", fake)
    rates = {"a": 1.0, "b": 1.05, "c": 5.0, "d": 50.0}
    rows = [{"run_id": r, "assembly": "A1", "sweep_rate_hz_per_s": v} for r, v in rates.items()]
    loaded = {r["run_id"]: (r, None, {}, pd.DataFrame()) for r in rows}
    plan = [(r, 95.0, "m95") for r in rows]
    notes = []
    assert camp.assembly_coil(plan, loaded, {}, notes) == {"m95": (1050.0, 6e5)}
    assert calls == [("a", "fit"), ("b", "fit")] and "fitted on a, b" in notes[0]
    fits["b"] = (np.nan, np.nan)  # one of the two slowest does not ask for a coil: none held
    assert camp.assembly_coil(plan, loaded, {}, []) == {"m95": None}
