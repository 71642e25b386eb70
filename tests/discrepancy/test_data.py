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
