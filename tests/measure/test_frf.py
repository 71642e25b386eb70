"""Whole-record FRF (jointcal.measure.frf): H1 against analytic FRFs, the single-mode fit, units on read."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.io import read_run
from jointcal.measure.frf import h1_estimate, record_frf, zeta_at_quadrature
from jointcal.measure.modal import measure_run
from jointcal.models import G, MinistackModel, simulate
from jointcal.synth.daq import controlled_sweep
from tests._support.ingest import _write_csv

F0, ZETA = 100.0, 0.015  # Hz, damping ratio of the linear test structure
M = 1.0 / G  # 1 lbf weight
K = M * (2 * np.pi * F0) ** 2
FS = 1024.0


def _linear_record(eta: float, *, base: bool, noise: float = 0.0, seed: int = 0):
    """A linear SDOF swept 80-120 Hz at eta (exact linear propagation, from rest, 1 s of decay)."""
    rng = np.random.default_rng(seed)
    rate = eta * (F0 * ZETA) ** 2
    t, _, u = controlled_sweep(FS, 80.0, 120.0, rate, 1.0, rng=rng, ramp_s=0.05, tail_s=1.0, ripple=0.0,
                               distortion=(0.0, 0.0))
    model = MinistackModel(m=M, k=K, zeta_v=ZETA)
    if base:  # base acceleration u (g): response = absolute acceleration
        ref, resp = u, simulate(model, u, FS).response_g
    else:  # force u (lbf) on a fixed base == base excited by -u / (m G)
        ref, resp = u, simulate(model, -u / (M * G), FS).response_g + u / (M * G)
    if noise:
        ref = ref + noise * ref.std() * rng.standard_normal(ref.size)
        resp = resp + noise * resp.std() * rng.standard_normal(resp.size)
    return t, ref, resp, rate


def _analytic_accelerance(f):
    """a / F of the SDOF (g/lbf): -w^2 / (k - m w^2 + i c w) / G."""
    w = 2 * np.pi * f
    return -(w**2) / (K - M * w**2 + 1j * w * 2 * ZETA * np.sqrt(K * M)) / G


@pytest.mark.parametrize("eta", [0.5, 20.0])
def test_h1_of_a_linear_structure_is_its_analytic_frf(eta):
    """Any sweep rate: within 0.5% in magnitude near the peak, resonance within 0.05%, zeta within 1%.

    (The whole record holds the sweep and the decay; the simulation is exact for a
    linear structure, so the bounds leave room only for the 0.3% noise added.)
    """
    _, ref, resp, _ = _linear_record(eta, base=False, noise=0.003)
    tab, fit = record_frf(ref, resp, FS, "force", (80.0, 120.0))
    f = tab["freq_hz"].to_numpy()
    H = (tab["h1_re"] + 1j * tab["h1_im"]).to_numpy()
    near = np.abs(f - F0) <= 2 * ZETA * F0
    err = np.abs(np.abs(H[near]) / np.abs(_analytic_accelerance(f[near])) - 1)
    print(f"\neta {eta}: |H1| err max {err.max():.2e}; f_n {fit.f_n_hz:.5f} Hz, f_quad {fit.f_quad_hz:.5f} Hz, "
          f"zeta {fit.zeta:.5f}, residual {fit.residual:.1e}")
    assert err.max() < 5e-3
    assert fit.f_n_hz == pytest.approx(F0, rel=5e-4)
    assert fit.f_quad_hz == pytest.approx(F0, rel=5e-4)
    assert fit.zeta == pytest.approx(ZETA, rel=0.01)
    assert fit.residual < 0.01 and fit.truncated < 0.01
    # the band-averaged coherence is a noise diagnostic only where H is flat over its 5 lines
    # (5 / T well inside the half-power band); over a short record it has a resolution bias
    T = ref.size / FS
    if 5 / T < 0.2 * 2 * ZETA * F0:
        assert tab["coherence"][near].min() > 0.99


def test_base_driven_ratio_and_energy_balance_damping():
    """z / a_base of a linear SDOF: quadrature at f_n; G / (2 w^2 |z / a_b|) is zeta."""
    _, ref, resp, _ = _linear_record(5.0, base=True)
    _, fit = record_frf(ref, resp, FS, "base", (80.0, 120.0))
    assert fit.f_quad_hz == pytest.approx(F0, rel=5e-4)
    assert zeta_at_quadrature(fit) * G / fit.modal_constant == pytest.approx(ZETA, rel=0.01)
    assert fit.modal_constant == pytest.approx(G, rel=0.01)  # z / a_b = -G / (w_n^2 - w^2 + ...) in/g


def test_welch_of_one_segment_is_the_ratio_of_transforms():
    """H1 from csd/welch with one boxcar segment is Y / X line by line (no averaging bias)."""
    rng = np.random.default_rng(1)
    x, y = rng.standard_normal(256), rng.standard_normal(256)
    tab = h1_estimate(x, y, 100.0, pad=1)
    X, Y = np.fft.rfft(x - np.median(x)), np.fft.rfft(y - np.median(y))
    H = (tab["h1_re"] + 1j * tab["h1_im"]).to_numpy()
    np.testing.assert_allclose(H[1:-1], (Y / X)[1:-1], rtol=1e-9)


SWEEP_FIT_KEYS = ("f_res_hz", "zeta_res", "q_in", "eta", "f_sweep_hz", "zeta_sweep", "modal_constant_re",
                  "modal_constant_im", "modal_slope_re", "modal_slope_im", "q_peak_in")  # q_peak_in: at f_res_hz


def test_response_in_m_s2_gives_the_same_modal_table(tmp_path):
    t, ref, resp, rate = _linear_record(2.0, base=False)
    _write_csv(tmp_path / "g.csv", {"time_s": t, "force_lbf": ref, "response_accel_g": resp})
    _write_csv(tmp_path / "si.csv", {"time_s": t, "force_lbf": ref, "response_accel_m_s2": resp * 9.80665})
    a, b = read_run(tmp_path / "g.csv"), read_run(tmp_path / "si.csv")
    assert list(b.columns) == ["time_s", "force_lbf", "response_accel_g"]
    row = dict(run_id="r", assembly="a", sequence=1, level_lbf=1.0, direction="up", f_start_hz=80.0,
               f_stop_hz=120.0, sweep_rate_hz_per_s=rate, sample_rate_hz=FS)
    pa, pb = measure_run(a, row, modal_kw={"mass_lbf": 1.0})[2], measure_run(b, row, modal_kw={"mass_lbf": 1.0})[2]
    for key, v in pa.items():
        if isinstance(v, float) and np.isfinite(v):
            # the fits' relative misfits of a noise-free record are float round-off themselves (< 1e-5):
            # equal to 1e-7 absolute; the iterative fits (least squares stops at relative cost changes of
            # 1e-8, i.e. parameters to ~1e-4) to 1e-5 relative (0.001%) from a rounding-level change of the input,
            # everything else to 1e-8
            tol = 1e-5 if key in SWEEP_FIT_KEYS else 1e-8
            assert pb[key] == pytest.approx(v, rel=tol, abs=1e-7 if key.endswith("_residual") else 0), key
        else:
            assert pb[key] == v or (v != v and pb[key] != pb[key]), key
    assert pa["f_res_method"] == "sweep_fit" and pa["zeta_sweep"] == pytest.approx(ZETA, rel=0.01)
    assert pa["f_res_hz"] == pytest.approx(F0, rel=5e-4) and pa["zeta_frf"] == pytest.approx(ZETA, rel=0.01)


def test_a_mode_is_not_mistaken_for_noise_over_w_squared():
    """A chirp from 0.5 Hz over a lightly damped 18 Hz mode, 2% response noise (the shape of a real beam
    record): noise divided by w^2 makes peaks of the displacement ratio near 0.5 Hz as high as the mode's,
    at low coherence. The fit takes the mode (the closed-form pole), not those; taking the largest peak
    regardless of coherence took one of them on this record."""
    from jointcal.measure.modefit import fit_mode

    fs, f0, zeta = 128.0, 18.0, 0.005
    model = MinistackModel(m=M, k=M * (2 * np.pi * f0) ** 2, zeta_v=zeta)
    rng = np.random.default_rng(3)
    t, _, u = controlled_sweep(fs, 0.5, 40.0, 5.0, 1.0, rng=rng, ramp_s=0.05, tail_s=2.0, ripple=0.0,
                               distortion=(0.0, 0.0))
    resp = simulate(model, -u / (M * G), fs).response_g + u / (M * G)
    resp = resp + 0.02 * resp.std() * rng.standard_normal(resp.size)
    tab, fit = record_frf(u, resp, fs, "force", (0.5, 40.0))
    assert fit.f_n_hz == pytest.approx(f0, rel=2e-3)
    X = (tab["x_re"] + 1j * tab["x_im"]).to_numpy()
    naive = fit_mode(tab["freq_hz"].to_numpy(), X, (0.5, 40.0), modal_phase=0.0)
    assert naive.f_n_hz < 5.0  # the same fit without the coherence: a noise peak
