"""The frames the discrepancy fits use (jointcal.discrepancy.data): frames whose window reaches past the sweep's
commanded span are left out (`within_sweep`), placed in time, not by their drive frequency.

Oracle: the sweep's line f = f_start + rate (t - t0) written down by hand."""
from __future__ import annotations

import numpy as np

from jointcal.discrepancy.data import within_sweep

ROW = {"f_start_hz": 70.0, "f_stop_hz": 130.0, "sweep_rate_hz_per_s": 3.0}  # 20 s, t0 = 0.1 s below
L = 0.2  # window, s


def _frames(direction: str = "up"):
    t = 0.07 + 0.05 * np.arange(405)  # to 20.27 s; no frame's window ends on a boundary
    f = 70.0 + 3.0 * (t - 0.1) if direction == "up" else 130.0 - 3.0 * (t - 0.1)
    on = (t > 0.1) & (t < 20.1)
    return t, f, on


def test_frames_whose_window_reaches_past_either_end_are_left_out():
    t, f, on = _frames()
    keep = within_sweep(t, f, on, ROW, L)
    assert np.array_equal(keep, (t - L / 2 >= 0.1) & (t + L / 2 <= 20.1))
    assert np.isclose(t[keep][0], 0.22) and np.isclose(t[keep][-1], 19.97)


def test_a_bent_ridge_at_the_stop_does_not_keep_the_stop_frame():
    """The ridge's frequency near the end reads a few tenths of a Hz off the line (the beam's eta-2 runs): the
    frame at the stop stays out whichever way it bends."""
    t, f, on = _frames()
    for bend in (-0.3, 0.3):
        g = f.copy()
        g[t > 19.9] += bend
        keep = within_sweep(t, g, on, ROW, L)
        assert not keep[np.argmin(np.abs(t - 20.07))] and keep[np.argmin(np.abs(t - 19.5))]


def test_a_down_sweep_and_a_row_without_its_sweep():
    t, f, on = _frames("down")
    row = {**ROW, "f_start_hz": 130.0, "f_stop_hz": 70.0}
    keep = within_sweep(t, f, on, row, L)
    assert np.array_equal(keep, (t - L / 2 >= 0.1) & (t + L / 2 <= 20.1))
    assert within_sweep(t, f, on, {}, L).all() and within_sweep(t, f, on, ROW, None).all()


def test_frames_off_the_manifests_line_are_all_kept():
    """A sweep the manifest does not describe (here logarithmic over the same ends): no frame is placed by it."""
    t, _, on = _frames()
    f = 70.0 * (130.0 / 70.0) ** np.clip((t - 0.1) / 20.0, 0, 1)
    assert within_sweep(t, f, on, ROW, L).all()


def test_a_fast_chirps_drive_is_the_whole_run_and_the_fast_model_follows_its_time_simulation():
    """A voltage chirp from 20 to 200 Hz at 100 Hz/s through the beam's mode (98 Hz, zeta 1.4%: eta 55, a lab's
    fast chirp, the real records' kind): the half-power band is crossed in a fiftieth of the decay time, and each
    envelope window (0.4 s) spans 40 Hz. Oracle: the exact time simulation of the same model (`simulate_record`),
    read by the modal stage. The fits' drive holds every driven frame of the run, not only the band's, so the
    slow flow is integrated from well below the resonance and over each frame's whole window: the fast model's
    envelope follows the time simulation to 0.1 dB and 0.5 deg at every fitted frame whose window the drive
    covers (measured 0.06 dB, 0.10 deg). With the band's frames alone for the drive, the band's last frames, their
    windows past the drive, took the first-order envelope: 0.81 and 0.17 dB off here, and the drive covered three
    frames (on the real records of this kind, the floor E 30.1 against the scatter, 0.99 now). The first two frames, whose windows reach before the first frame read at full drive, take
    the first-order envelope: 1-2 dB off (not asserted)."""
    from jointcal.discrepancy.data import run_envelope, scale_arrays
    from jointcal.discrepancy.fit import Objective, candidate
    from jointcal.measure.modal import measure_run
    from jointcal.validate.drive import simulate_record
    from tests._support.beam_runs import BEAM, BEAM_JOINT, GAINS, _run, beam_space

    rec, row = _run("voltage", 0.3, rate=100.0, f0=20.0, f1=200.0)
    row.pop("drive_gain")
    sim = simulate_record(BEAM, rec, {**row, "drive_gain": GAINS["voltage"]})
    env, _, props = measure_run(sim, row)
    run = run_envelope(env, {**row, **props, "drive_gain": GAINS["voltage"]}, *scale_arrays(None))
    eta = 100.0 / (props["f_res_hz"] * props["zeta_res"]) ** 2
    assert run is not None and eta > 50
    assert run.drive.f_hz.max() > 1.6 * props["f_res_hz"]  # past the band's 1.4 f_res: the ringing integrated
    scales = {"K0": BEAM.k + BEAM.iwan.KT, "f0": BEAM.f0_hz, "q": float(props["q_in"])}
    c = candidate("baseline", beam_space(), BEAM.m, scales)
    d = Objective(c, [run]).at(BEAM_JOINT).predict(BEAM_JOINT, 0) / run.T
    L = run.drive.window_s
    covered = (run.t_s - L / 2 >= run.drive.t_s[0]) & (run.t_s + L / 2 <= run.drive.t_s[-1])
    err_db, err_deg = np.abs(20 * np.log10(np.abs(d))), np.abs(np.degrees(np.angle(d)))
    print(f"\neta {eta:.0f}, {run.f_hz.size} frames, {covered.sum()} covered by the drive: "
          f"max {err_db[covered].max():.3f} dB, {err_deg[covered].max():.3f} deg; all: {np.round(err_db, 2)} dB")
    assert covered.sum() >= 4
    assert err_db[covered].max() < 0.1 and err_deg[covered].max() < 0.5
