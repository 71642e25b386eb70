"""jointcal.spectral, the helpers below io and measure, against closed forms."""
import numpy as np
import pytest

from jointcal.spectral import parabola_vertex, peak_frequency


@pytest.mark.parametrize("x0, a, c", [(0.3, -2.0, 5.0), (-0.45, -0.1, 1.0), (0.0, -7.0, -3.0)])
def test_parabola_vertex_is_exact_for_a_parabola(x0, a, c):
    y = a * (np.array([-1.0, 0.0, 1.0]) - x0) ** 2 + c
    delta, top = parabola_vertex(*y)
    assert float(delta) == pytest.approx(x0, abs=1e-12)
    assert float(top) == pytest.approx(c, rel=1e-12)


def test_parabola_vertex_gives_no_offset_without_a_peak():
    delta, top = parabola_vertex(np.array([1.0, 0.0]), np.array([2.0, 0.0]), np.array([3.0, 1.0]))
    assert np.array_equal(delta, [0.0, 0.0]) and np.array_equal(top, [2.0, 0.0])


@pytest.mark.parametrize("f", [150.0, 2345.6, 5000.3])
def test_peak_frequency_of_a_tone(f):
    """A tone of 400 samples: one FFT line is 32 Hz, the padded peak refined on the log to well under 1 Hz."""
    fs = 12800.0
    x = np.sin(2 * np.pi * f * np.arange(400) / fs)
    assert abs(peak_frequency(x, fs) - f) < 1.0


def test_peak_frequency_of_a_free_decay_without_a_window_and_above_lo():
    """A decaying tone (it tapers itself: no window) beside a stronger slow drift that `lo` leaves out."""
    fs, f, zeta = 2048.0, 18.5, 0.01
    t = np.arange(int(8 * fs)) / fs
    x = np.exp(-zeta * 2 * np.pi * f * t) * np.sin(2 * np.pi * f * t) + 5.0 * np.sin(2 * np.pi * 0.2 * t)
    assert abs(peak_frequency(x, fs, pad=8, window=False, lo=2.0) - f) < 1e-4 * f  # measured 6e-6
    assert peak_frequency(x, fs, pad=8, window=False, lo=0.05) < 1.0  # the drift, when not left out


def test_peak_frequency_treats_non_finite_samples_as_zero_and_a_silent_record_as_0_hz():
    fs, f = 1000.0, 100.0
    x = np.sin(2 * np.pi * f * np.arange(500) / fs)
    x[[3, 40]] = np.nan, np.inf
    assert abs(peak_frequency(x, fs) - f) < 1.0
    assert peak_frequency(np.zeros(64), fs) == 0.0
