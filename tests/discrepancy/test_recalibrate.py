"""The posterior of a grown parameter space: the joint's six plus an effect's, on a virtual campaign.

The campaign comes from the virtual lab (`jointcal.synth`: exact-Iwan time simulation, DAQ
chain) with the response channel reading 12% high; the fast envelope model is fitted to its
measured envelopes. The recalibration samples the grown space (joint + sensor_gain) with
the calibration's GA and the posterior's sampler; its 90% intervals must hold the truth the
campaign was made from.
"""
from pathlib import Path

import numpy as np
import pytest

from jointcal.calibrate import CalibrateSettings
from jointcal.calibrate.space import PARAMS
from jointcal.discrepancy.data import run_envelope, scale_arrays
from jointcal.discrepancy.fit import HELD, Objective, candidate
from jointcal.discrepancy.recalibrate import recalibrate
from jointcal.models import G
from jointcal.posterior import LogPosterior

TRUTH = dict(zip(PARAMS, (280.0, 1.1e6, -0.6, 0.01, 7.0e5, 0.002)))
GAIN = 1.12
SPACE = CalibrateSettings().space


def _campaign(folder: Path) -> list:
    """Envelopes of a virtual-lab campaign (other joint than the example, 10 kHz, 400 Hz/s) with a hidden gain."""
    from jointcal.io import read_manifest, read_run
    from jointcal.measure.modal import measure_run
    from jointcal.synth import generate

    spec = {"seed": 11, "sample_rate_hz": 10000.0,
            "sweep": {"f_start_hz": 1600.0, "f_stop_hz": 2800.0, "rate_hz_per_s": 400.0},
            "series": [{"level_g": 1.0, "directions": ["up", "down"], "repeats": 1},
                       {"level_g": 4.0, "directions": ["up"], "repeats": 1},
                       {"level_g": 10.0, "directions": ["up", "down"], "repeats": 1}],
            "assemblies": {"a": TRUTH}, "effect": {"name": "sensor_gain", "params": {"gain": GAIN}}}
    generate(spec, folder, folder.parent / "truth.json")
    sdb, sdeg = scale_arrays(None)  # the floors: the campaign has no repeats
    runs = []
    for row in read_manifest(folder / "manifest.csv").to_dict("records"):
        env, _, props = measure_run(read_run(folder / row["file"]), row)
        run = run_envelope(env, {**row, **props}, sdb, sdeg, max_frames=60)
        if run is not None:
            runs.append(run)
    return runs


def test_a_grown_space_is_sampled_through_the_modal_likelihood_by_name():
    """The modal likelihood takes a grown space: the joint's columns map to y by name, the effect's pass as x."""
    from jointcal.calibrate import ModalData

    grown = SPACE.grow(["gain"], [0.5], [2.0], [True], ["-"])
    q = np.geomspace(1e-5, 1e-4, 5)
    data = ModalData("a", tuple("abcde"), np.ones(5), q, np.full(5, 2200.0), np.full(5, 0.01), "phase_resonance",
                     (1e-3, 1e-2), ())
    lp = LogPosterior(data, grown, 2.65 / G)
    assert lp.ndim == 9 and lp.names[6] == "log10_gain" and lp.sample_names[6] == "gain"
    x = np.r_[grown.to_unit(grown.vector({**TRUTH, "gain": GAIN})) * (grown.x_hi - grown.x_lo) + grown.x_lo,
              -2.5, -1.5]
    np.testing.assert_allclose(lp.to_x(lp.to_y(x)), x, rtol=1e-12, atol=1e-12)
    assert lp.physical(x)[grown.index("gain")] == pytest.approx(GAIN)
    # the effect's column does not enter the modal read-outs: its log-posterior is flat in it
    x2 = x.copy()
    x2[grown.index("gain")] = np.log10(1.5)
    assert lp(lp.to_y(x)[None])[0] == pytest.approx(lp(lp.to_y(x2)[None])[0], rel=1e-12)


@pytest.mark.slow
def test_the_posterior_of_joint_plus_sensor_gain_covers_the_truth(tmp_path):
    runs = _campaign(tmp_path / "c")
    assert len(runs) == 5
    c = candidate("sensor_gain", SPACE, 2.65 / G)
    assert c.grown.names == (*PARAMS, "gain")
    start = {**TRUTH, "Fs": 1.1 * TRUTH["Fs"], "KT": 0.95 * TRUTH["KT"], "k": 1.05 * TRUTH["k"],
             "zeta_v": 1.2 * TRUTH["zeta_v"]}  # a calibration slightly off, as the joint's calibration gives
    fit = Objective(c, runs).fit(SPACE.vector(start), starts=3, max_nfev=25, refresh=1)
    rec = recalibrate(c, runs, [fit], generations=3, population=24, walkers=24, steps=300, max_nfev=25)
    q = rec.quantiles
    print("\n" + q.assign(truth=[*[TRUTH[p] for p in PARAMS], GAIN]).to_string(), f"\nE {rec.fit.E:.2f}")
    truth = {**TRUTH, "gain": GAIN}
    sampled = [p for p in c.grown.names if p not in HELD]
    for p in sampled:
        assert q.at[p, "q05"] <= truth[p] <= q.at[p, "q95"], f"{p}: truth {truth[p]:.4g} outside " \
                                                             f"[{q.at[p, 'q05']:.4g}, {q.at[p, 'q95']:.4g}]"
    # the gain is measured, not left to its prior [0.5, 2]: its interval is within a few percent
    assert q.at["gain", "q95"] / q.at["gain", "q05"] < 1.1


def test_ring_down_fits_the_data_do_not_tell_apart_keep_the_one_without_a_knee_on_the_top_window():
    """`recalibrate._chosen` on two fits of the Ministack's joint: one with its macroslip onset phi_max (eq. 3.7,
    computed here from its Fs, KT, chi, beta) just under the top window's start, the other all in microslip, E 0.90
    and 0.92. Over 40 residuals -2 ln L differs by 40 (0.92^2 - 0.90^2) / 1 = 1.5 < 3.84: the microslip fit is
    kept; over 400 (15) the data tell them apart and the lower E wins. Sweeps' runs (no `q_top`): the lowest E."""
    from types import SimpleNamespace

    from jointcal.discrepancy.fit import Fit
    from jointcal.discrepancy.recalibrate import _chosen
    from jointcal.models.iwan import derived
    from tests._support.envelopes import M, SPACE, TRUTH

    c = candidate("baseline", SPACE, M)
    slip = TRUTH.copy()
    phi = derived(*TRUTH[:4])[0]
    top = np.array([0.5, 0.8, 1.02]) * phi  # the truth's onset just under the top window's start
    knee = Fit("baseline", TRUTH, 0.90, np.eye(6), 1)
    slip[0] = 3 * TRUTH[0]  # three times the slip force: phi_max three times as far
    assert derived(*slip[:4])[0] > top.max()
    micro = Fit("baseline", slip, 0.92, np.eye(6), 1)
    runs = [SimpleNamespace(q_in=top / 1.1, q_top=top)]
    assert _chosen([knee, micro], c, runs, 40) is micro
    assert _chosen([knee, micro], c, runs, 400) is knee
    assert _chosen([knee, micro], c, [SimpleNamespace()], 40) is knee
