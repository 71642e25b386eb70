"""The shared read-outs of jointcal.measure.peaks and the one excitation rule of jointcal.io, against closed forms."""
import numpy as np
import pandas as pd
import pytest

from jointcal.measure.peaks import (
    anchored_phase, full_drive, half_power, half_power_lines, phase_crossing, transmissibility,
)


@pytest.mark.parametrize("zeta", [0.005, 0.02, 0.05])
def test_half_power_of_one_mode_gives_its_damping(zeta):
    """|X| = 1/|w_n^2 - w^2 + 2 i zeta w_n w| falls to 1/sqrt(2) of its peak at f_n (1 -+ zeta) to first order
    (docs/physics.md, section 5): the bandwidth over twice the peak frequency is zeta within O(zeta^2)."""
    fn = 2000.0
    f = np.linspace(0.8 * fn, 1.2 * fn, 200001)
    w, wn = 2 * np.pi * f, 2 * np.pi * fn
    a = 1.0 / np.abs(wn**2 - w**2 + 2j * zeta * wn * w)
    ip = int(np.argmax(a))
    lo, hi = half_power(f, a, ip)
    assert (hi - lo) / (2 * f[ip]) == pytest.approx(zeta, rel=3 * zeta**2)  # measured 2 zeta^2
    i, j = half_power_lines(a, ip)
    assert f[i] <= lo <= f[i + 1] and f[j - 1] <= hi <= f[j]


@pytest.mark.parametrize("rising", [True, False])
def test_half_power_with_one_side_outside_the_lines_is_nan(rising):
    """A peak at the record's edge has no bandwidth: NaN (the run is flagged), never a width of zero."""
    f = np.linspace(0.0, 1.0, 11)
    a = np.linspace(1.0, 2.0, 11) if rising else np.linspace(2.0, 1.0, 11)
    ip = 10 if rising else 0
    lo, hi = half_power(f, a, ip)
    assert np.isnan(lo) and np.isnan(hi)
    assert half_power_lines(a, ip)[1 if rising else 0] is None


def test_phase_crossing_of_one_mode_is_its_natural_frequency():
    """z / a_base = -1/(w_n^2 - w^2 + 2 i zeta w_n w) is at +90 deg exactly at w_n (docs/physics.md, section 4)."""
    fn, zeta = 2200.0, 0.02
    f = np.linspace(1500.0, 2900.0, 1401)
    w, wn = 2 * np.pi * f, 2 * np.pi * fn
    X = -1.0 / (wn**2 - w**2 + 2j * zeta * wn * w)
    ph = anchored_phase(X * np.exp(4j * np.pi), np.pi / 2)  # two whole turns off: anchored back
    assert abs(np.median(ph) - np.pi / 2) <= np.pi
    i, u = phase_crossing(f, ph, np.pi / 2, 2000.0)
    assert f[i] + u * (f[i + 1] - f[i]) == pytest.approx(fn, rel=1e-6)
    assert phase_crossing(f, ph, 3 * np.pi, fn) is None


def _env(ref, resp, on=None, bad=None):
    n = len(ref)
    return pd.DataFrame(dict(ref_re=np.real(ref), ref_im=np.imag(ref), resp_re=np.real(resp), resp_im=np.imag(resp),
                             drive_on=np.ones(n, bool) if on is None else on,
                             bad=np.zeros(n, bool) if bad is None else bad))


def test_full_drive_leaves_out_ramps_bad_and_silent_frames():
    ref = np.r_[np.linspace(0.0, 1.0, 10), np.ones(30), np.linspace(1.0, 0.0, 10)]
    on = ref > 0.05
    bad = np.zeros(ref.size, bool)
    bad[20] = True
    use = full_drive(_env(ref, 2 * ref, on=on, bad=bad))
    assert use[10:20].all() and not use[20] and use[21:40].all()
    assert not use[:8].any() and not use[42:].any()  # the ramps below 0.8 of the median


def test_transmissibility_is_response_over_reference():
    ref = np.array([1.0 + 1.0j, 2.0, -1.0j])
    resp = np.array([3.0, 1.0 + 2.0j, 4.0])
    assert np.allclose(transmissibility(_env(ref, resp)), resp / ref, rtol=0, atol=1e-15)
