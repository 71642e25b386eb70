"""Modal stage (jointcal.measure.modal): resonance and damping against known truth, flags,
scatter, force-driven runs, and one backbone whatever the sweep.

One backbone whatever the sweep: force- and voltage-driven virtual rigs with a second mode. A jointed 100 Hz beam
with a linear 230 Hz mode at the driving point, on an open-loop shaker (`tests/_support/rigs.py`), read by the
modal stage: each run's (q_in, f_res_hz, zeta_res) against the truth's curve at its own q_in (the structure's
first-harmonic balance for a force, the coupled rig's pole for a voltage), and q_in against the amplitude the
mode reached. The full matrix (eta 0.5-500, up and down, three seeds) is tests/benchmarks/accept_backbone.py; here
a chirp at eta 5 that crosses both modes, an impulse-like one at eta 500 and a slow sweep at eta 0.5, with 2%
noise, at two levels."""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointcal.io import write_run
from jointcal.measure.envelopes import envelopes
from jointcal.measure.modal import modal_properties
from jointcal.measure.scatter import scatter
from jointcal.models import G, IwanParams, MinistackModel, harmonic_balance, simulate
from jointcal.synth import generate
from jointcal.synth.daq import controlled_sweep
from tests._support import rigs as _rigs
from tests._support.modal_helpers import against_truth, modal_table


@pytest.fixture(scope="module")
def default_campaign(default_campaign_dir, default_modal):
    """The default generator (Table 3.1/3.2, 300 Hz/s, 0.3% noise), no hidden effect (made once: conftest.py)."""
    table = default_modal.copy()
    return table, against_truth(table, default_campaign_dir.parent / "truth.json")


@pytest.mark.slow
def test_resonance_and_damping_match_truth(default_campaign):
    table, err = default_campaign
    f_err, z_err, hp_err = err["f_err"].abs(), err["zeta_err"].abs(), err["zeta_hp_err"]
    print(f"\nf_res: median {f_err.median() * 100:.4f}%, max {f_err.max() * 100:.4f}%; "
          f"zeta (phase resonance): median {z_err.median() * 100:.2f}%, max {z_err.max() * 100:.2f}%; "
          f"half-power bias: median {hp_err.median() * 100:+.1f}% (range {hp_err.min() * 100:+.1f}.."
          f"{hp_err.max() * 100:+.1f}%); eta {table['eta'].min():.2f}..{table['eta'].max():.2f}")
    assert f_err.median() < 2e-4 and f_err.max() < 5e-4
    assert z_err.median() < 0.01
    assert hp_err.median() > 0.05  # the paper's estimator reads high: amplitudes mixed, sweep-rate bias
    assert (table["flags"].fillna("") == "").all()
    assert (table["f_res_method"] == "quadrature").all()


@pytest.mark.slow
def test_up_and_down_agree_within_scatter(default_campaign):
    """No direction bias: up/down differences are as scattered as the repeats, centred on 0.

    (Pairs are compared as they are; each sweep's amplitude differs a little with the
    controller's ripple, and the frequency follows the amplitude.)
    """
    table, _ = default_campaign
    sc = scatter(table)
    pooled = sc[sc.source == "pooled"].set_index(["assembly", "quantity"])["rel_std"]
    for asm, g in table.groupby("assembly"):
        d = []
        for (lev, _seq), gl in g.assign(pair=(g["sequence"] + 1) // 2).groupby(["level_g", "pair"]):
            up = gl[gl.direction == "up"]["f_res_hz"]
            down = gl[gl.direction == "down"]["f_res_hz"]
            if len(up) and len(down):
                d.append(up.iloc[0] / down.iloc[0] - 1)
        d = np.array(d)
        assert len(d) >= 6
        assert abs(d.mean()) < 3 * d.std(ddof=1) / np.sqrt(d.size)
        assert np.abs(d).max() < 4 * pooled[(asm, "f_res_hz")]
    assert (pooled.xs("f_res_hz", level=1) < 1e-3).all()
    assert (pooled.xs("zeta_phase_resonance", level=1) < 0.02).all()


FIRST = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}


@pytest.mark.slow
@pytest.mark.parametrize("rate, method", [(2000.0, "quadrature_slope"), (12000.0, "frf_fit")])
def test_fast_sweep_flags_eta_and_keeps_resonance_unbiased(tmp_path, rate, method):
    generate({"seed": 2, "sweep": {"f_start_hz": 1500.0, "f_stop_hz": 2700.0, "rate_hz_per_s": rate},
              "series": [{"level_g": 1.0, "directions": ["up", "down"]}], "assemblies": {"first": FIRST}},
             tmp_path / "c", tmp_path / "t.json")
    err = against_truth(modal_table(tmp_path / "c"), tmp_path / "t.json")
    print(f"\nrate {rate}: eta {err['eta'].round(2).tolist()}, f err {(err['f_err'] * 100).round(4).tolist()}%, "
          f"method {err['f_res_method'].tolist()}")
    assert err["flags"].str.contains("eta_high").all()
    assert (err["f_res_method"] == method).all()
    assert err["f_err"].abs().max() < (1e-3 if method == "quadrature_slope" else 2e-3)


@pytest.mark.slow
def test_channel_delay_shifts_quadrature_as_2_pi_f_tau_predicts(tmp_path):
    tau = 40e-6
    spec = {"seed": 4, "sweep": {"f_start_hz": 1500.0, "f_stop_hz": 2700.0, "rate_hz_per_s": 150.0},
            "series": [{"level_g": 1.0, "directions": ["up", "down"]}, {"level_g": 5.0, "directions": ["up"]}],
            "assemblies": {"first": FIRST}}
    generate(spec, tmp_path / "a", tmp_path / "a.json")
    generate({**spec, "effect": {"name": "channel_delay", "params": {"tau_s": tau}}}, tmp_path / "b", tmp_path / "b.json")
    a, b = modal_table(tmp_path / "a"), modal_table(tmp_path / "b")
    # (1) at the delay-free resonance the delayed record's z is 2 pi f tau past quadrature;
    # (2) the resonance moves to where the delay-free phase curve reaches pi/2 + 2 pi f tau
    from jointcal.io import read_manifest, read_run

    def quasi_steady_phase(folder, row, tau_g):
        env, _ = envelopes(read_run(folder / row["file"]), row)
        e = env[env.drive_on]
        ph = np.unwrap(np.angle((e.z_re + 1j * e.z_im) / (e.ref_re + 1j * e.ref_im)))
        sgn = 1 if row["f_stop_hz"] > row["f_start_hz"] else -1
        f = e.f_drive_hz.to_numpy() - sgn * row["sweep_rate_hz_per_s"] * tau_g  # undo the sweep's lag
        o = np.argsort(f)
        ph = ph[o] - 2 * np.pi * np.round((np.median(ph) - np.pi / 2) / (2 * np.pi))
        return f[o], ph

    man = read_manifest(tmp_path / "b" / "manifest.csv")
    for i, row in enumerate(man.to_dict("records")):
        fb, phb = quasi_steady_phase(tmp_path / "b", row, b.loc[i, "group_delay_s"])
        fa, pha = quasi_steady_phase(tmp_path / "a", row, a.loc[i, "group_delay_s"])
        f_a = a.loc[i, "f_res_hz"]
        assert np.interp(f_a, fb, phb) - np.pi / 2 == pytest.approx(-2 * np.pi * f_a * tau, rel=0.06)
        near = np.abs(fa - f_a) < 60
        gap = pha[near] - (np.pi / 2 + 2 * np.pi * fa[near] * tau)
        k = np.flatnonzero(gap[:-1] * gap[1:] <= 0)[0]
        f_pred = fa[near][k] - gap[k] * (fa[near][k + 1] - fa[near][k]) / (gap[k + 1] - gap[k])
        print(f"\n{row['run_id']}: shift {b.loc[i, 'f_res_hz'] - f_a:+.2f} Hz, predicted {f_pred - f_a:+.2f} Hz")
        assert b.loc[i, "f_res_hz"] - f_a == pytest.approx(f_pred - f_a, rel=0.05)


@functools.cache
def _force_simulation():
    """The force-driven slug's exact time simulation, made once for the driving-point and the remote sensor's
    records (the same force and motion; they differ in the sensor read): model, t, F, simulation, and the state of
    the generator the noise is then drawn from."""
    m = 2.65 / G
    model = MinistackModel(m=m, k=FIRST["k"], zeta_v=FIRST["zeta_v"], iwan=IwanParams(313, 1.02e6, -0.65, 0.004))
    fs = 25600.0
    rng = np.random.default_rng(0)
    t, _, F = controlled_sweep(fs, 1600.0, 2700.0, 150.0, 4.0, rng=rng, tail_s=0.3)  # 4 lbf, then free decay
    sim = simulate(model, -F / (m * G), fs)  # a fixed base forced by F == base excited by -F/m
    return model, t, F, sim, rng.bit_generator.state


def _force_campaign(folder: Path, response="driving_point"):
    """A force-driven run: slug on the joint, a shaker with force gauge drives the slug."""
    model, t, F, sim, state = _force_simulation()
    m, fs = model.m, 25600.0
    rng = np.random.default_rng()
    rng.bit_generator.state = state  # the noise each record would draw after its own sweep, as if made alone
    acc = sim.response_g + F / (m * G)  # the slug's acceleration, g
    if response == "remote":  # a sensor near a node of this mode, dominated by other modes' mass line
        acc = 0.02 * acc - 0.8 * F / (m * G)  # (alpha = 40 > 1/(2 zeta): the phase never reaches 90 deg)
    acc = acc + 0.003 * acc.std() * rng.standard_normal(acc.size)
    write_run(folder / "runs" / "f1.csv", t, F, acc, kind="force")
    row = dict(run_id="f1", assembly="a", sequence=1, level_lbf=4.0, direction="up", f_start_hz=1600.0,
               f_stop_hz=2700.0, sweep_rate_hz_per_s=150.0, sample_rate_hz=fs, file="runs/f1.csv")
    pd.DataFrame([row]).to_csv(folder / "manifest.csv", index=False)
    return row, model, sim


def _force_measured(folder: Path) -> tuple[pd.DataFrame, dict]:
    """The force campaign in `folder` through envelopes and the modal read-out: (envelopes, modal row)."""
    from jointcal.io import ingest_campaign, read_run
    runs = ingest_campaign(folder)
    df = read_run(folder / "runs" / "f1.csv")
    env, meta = envelopes(df, runs.iloc[0].to_dict())
    return env, modal_properties(env, runs.iloc[0].to_dict(), rate_hz_per_s=meta.rate_hz_per_s, record=df)


@pytest.fixture(scope="module")
def force_driving_point(tmp_path_factory):
    """The driving-point force campaign, generated and measured once for the tests that read it."""
    folder = tmp_path_factory.mktemp("force_driving_point")
    _, model, _ = _force_campaign(folder)
    env, out = _force_measured(folder)
    return model, env, out


@pytest.mark.slow
def test_force_driven_driving_point(force_driving_point):
    model, env, out = force_driving_point
    p = model.iwan
    f, z = harmonic_balance(out["q_envelope_in"], p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    f_s, z_s = harmonic_balance(out["q_in"], p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    assert "level_lbf" in out and "level_g" not in out
    # force reference: the swept-mode fit at the amplitude reached (q_in); beside it the H1's quadrature at
    # the envelopes' amplitude there. The joint bends the constant-force peak (FRF fit residual above 2%),
    # which moves the fitted pole but neither of those; the flags are those of the value reported (the
    # sweep fit's: none)
    print(f"\nfit residual {out['frf_residual']:.3f}, f_frf {out['f_frf_hz']:.1f} Hz, quadrature "
          f"{out['f_frf_quad_hz']:.1f} Hz, sweep fit {out['f_res_hz']:.1f} Hz at {out['q_in']:.2e} in")
    assert out["f_res_method"] == "sweep_fit" and out["flags"] == "" and out["frf_residual"] > 0.02
    assert out["zeta_res"] == out["zeta_sweep"]
    assert out["q_in"] == pytest.approx(out["q_peak_in"], rel=0.05)  # the band-limited envelope peak
    assert out["f_res_hz"] == pytest.approx(float(f_s), rel=1e-3)
    assert out["zeta_sweep"] == pytest.approx(float(z_s), rel=0.05)
    assert out["f_frf_quad_hz"] == pytest.approx(float(f), rel=3e-4)
    assert out["zeta_phase_resonance"] == pytest.approx(float(z), rel=0.02)
    assert env["drive_on"].iloc[-20:].eq(False).all()  # the free decay is not taken for drive


@pytest.mark.slow
def test_force_driven_remote_sensor_gives_the_mode_at_its_own_amplitude(tmp_path, force_driving_point):
    """A sensor near a node (2% of the slug's motion) dominated by other modes' mass line: the envelope
    phase never reaches quadrature, and the swept-mode fit takes the mass line as its residual term and
    a modal constant of either sign. Its resonance and damping are the harmonic balance's at the joint's
    amplitude, the sensor's q_in / 0.02, and its modal constant 0.02 / m."""
    _, model, _ = _force_campaign(tmp_path, response="remote")
    remote = _force_measured(tmp_path)[1]
    driving = force_driving_point[2]
    p = model.iwan
    f_t, z_t = harmonic_balance(remote["q_in"] / 0.02, p.Fs, p.KT, p.chi, p.beta, model.k, model.m, model.zeta_v)
    print(f"\nremote: {remote['f_res_method']} {remote['f_res_hz']:.2f} Hz (truth {float(f_t):.2f}), zeta "
          f"{remote['zeta_res']:.4f} (truth {float(z_t):.4f}); FRF pole {remote['f_frf_hz']:.2f} Hz, driving "
          f"point's {driving['f_frf_hz']:.2f} Hz")
    assert remote["f_res_method"] == "sweep_fit" and "unusable" not in remote["flags"]
    assert remote["f_res_hz"] == pytest.approx(float(f_t), rel=1e-3)
    assert remote["zeta_res"] == pytest.approx(float(z_t), rel=0.05)
    assert remote["modal_constant_re"] == pytest.approx(0.02 / model.m, rel=0.03)
    assert remote["q_in"] / 0.02 == pytest.approx(driving["q_in"], rel=0.03)

@pytest.mark.slow
def test_a_run_is_read_with_the_config_modal_section_as_the_later_stages_pass_it(tmp_path):
    """Validation and discrepancy read one run at a time with the config's whole `modal` section
    (measure_run): its campaign-level switches (coil, on or off) do not reach the one-run read-out, which
    gives the same numbers as without them."""
    import yaml
    from tests._support.campaign import REPO, voltage_campaign

    from jointcal.io import read_manifest, read_run
    from jointcal.measure.modal import measure_run

    folder = voltage_campaign(tmp_path / "v")
    row = read_manifest(folder / "manifest.csv").iloc[0].to_dict()
    record = read_run(folder / row["file"], row)
    section = yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text())["modal"]
    plain = measure_run(record, row)[2]
    for coil in (False, True):
        props = measure_run(record, row, modal_kw={**section, "coil": coil})[2]
        assert props["f_res_method"] == plain["f_res_method"] == "sweep_fit"
        assert props["f_res_hz"] == plain["f_res_hz"] and props["zeta_res"] == plain["zeta_res"]


@pytest.mark.parametrize("ref, eta, direction", [("voltage", 5.0, "up"), ("force", 500.0, "down"),
                                                 ("voltage", 500.0, "up"), ("force", 0.5, "up")])
def test_read_outs_lie_on_the_truths_backbone(tmp_path, ref, eta, direction):
    levels = _rigs.levels_V()
    _rigs.campaign(tmp_path / "c", tmp_path / "t.json", ref=ref, eta=eta, direction=direction, seed=2,
                   levels=[levels[0], levels[2]])
    r = _rigs.read_out(tmp_path / "c", tmp_path / "t.json", ref)
    print("\n" + r[["method", "eta", "q_in", "f_err", "zeta_err", "q_err", "q_peak_err"]].to_string())
    assert (r["method"] == "sweep_fit").all() and (r["flags"] == "").all()
    assert r["eta"].min() > 0.2 * eta
    assert np.abs(r["f_err"]).max() < 1e-3
    assert np.abs(r["zeta_err"]).max() < 0.05
    assert np.abs(r["q_err"]).max() < 0.03
    assert r["q_in"].iloc[1] > 2 * r["q_in"].iloc[0]  # the levels reach different amplitudes
