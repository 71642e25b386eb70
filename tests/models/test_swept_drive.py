"""The fast envelope model of one mode under an open-loop force (issue 30, item 2): its floor measured.

Oracle: a virtual open-loop force rig (`jointcal.synth.shaker.simulate_rig`: the jointed beam of
`tests/_rigs.py` on its small shaker, driven by an amplifier's voltage chirp), whose gauge force
dips about five-fold and turns in phase within a few cycles at the resonance; the exact time
simulation of the same structural model driven by that recorded force
(`jointcal.validate.drive.simulate_record`), measured by the same envelopes (`measure_run`); against
the fast model (`swept_transmissibility`, read through `observed`) at the frames the discrepancy
fits use (`run_envelope`). The chirp starts and stops outside the fitted band (0.6-1.4 f_res), so
the drive's start and stop ramps, which ring the mode in both, are not among the compared frames.

E is the validation's, over the smallest repeat scatter the stage admits (0.05 dB, 0.3 deg:
`scale_arrays`' floors). Measured (linear / Iwan joint; rms dB, deg): the complex drive (magnitude
and phase against the sweep) E 0.01 / 0.01 at eta 0.5, 0.07 / 0.09 at eta 2 (0.003 dB, 0.03 deg),
6.6 / 4.6 at eta 10 (0.21-0.26 dB, 1.5-2.3 deg); the magnitude alone, as before, 0.61 / 0.60,
4.36 / 4.31 (0.12-0.13 dB, 1.6-1.7 deg) and 31 / 22-34. What is left at eta 10 is the window: the
frames are the Hann average of a force that rings within one window (a fine drive taken from the
record itself, which the fits do not have, brings it to about 2).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from tests._support.rigs import levels_V, rig, truth_curve
from jointcal.discrepancy.data import run_envelope, run_zeta, scale_arrays
from jointcal.discrepancy.fit import observed
from jointcal.measure.modal import measure_run
from jointcal.models import G, MinistackModel, swept_transmissibility
from jointcal.synth.daq import controlled_sweep
from jointcal.synth.shaker import simulate_rig
from jointcal.validate.drive import simulate_record

FS, OVERSAMPLE = 2048.0, 8  # the virtual lab's sample rate; the rig simulated 8x finer, as `synth.generate` does
GAIN = (complex(G), 0j, 2 * np.pi * 100.0)  # a force on the beam's 1 lbf mass: A = 1/m = G per lbf, real
HALF = 0.45  # the chirp crosses (1 -+ HALF) f_res: starts and stops outside the fitted band


def _joint(kind: str) -> MinistackModel:
    """The rig's beam (Iwan joint), or a linear beam of the same stuck stiffness and mass."""
    beam, _, _ = rig()
    if kind == "iwan":
        return beam
    return MinistackModel(m=beam.m, k=beam.k + beam.iwan.KT, zeta_v=0.012)


def _force_record(model: MinistackModel, eta: float) -> tuple[pd.DataFrame, dict]:
    """The gauge force of the open-loop rig under a voltage chirp at sweep-rate parameter eta (at the middle
    level's truth), sampled at FS, and its manifest row with the force's drive gain."""
    _, shaker, _ = rig()
    f, z = truth_curve("force", 3e-3)
    rate = eta * (f * z) ** 2
    lo, hi = (1 - HALF) * f, (1 + HALF) * f
    t, _, volts = controlled_sweep(FS * OVERSAMPLE, lo, hi, rate, levels_V()[1], rng=np.random.default_rng(0),
                                   ramp_s=0.05, tail_s=1.5, ripple=0.0, distortion=(0.0, 0.0))
    _, force, _ = simulate_rig(model, shaker, volts, FS * OVERSAMPLE)
    t, force, on = t[::OVERSAMPLE], force[::OVERSAMPLE], np.abs(volts[::OVERSAMPLE]) > 0
    rec = pd.DataFrame({"time_s": t, "force_lbf": force, "response_accel_g": np.zeros_like(t)})
    row = {"run_id": "r1", "assembly": "beam", "level_lbf": float(np.sqrt(2 * np.mean(force[on] ** 2))),
           "direction": "up", "f_start_hz": lo, "f_stop_hz": hi, "sweep_rate_hz_per_s": rate, "sample_rate_hz": FS,
           "sequence": 1, "drive_gain": GAIN}
    return rec, row


def _errors(model: MinistackModel, run, props: dict, drive) -> tuple[np.ndarray, np.ndarray, float]:
    """dB and degree errors of the fast model (driven by `drive`) against the run's measured frames, and E."""
    T = swept_transmissibility(model, drive, run.t_s, f_res_hz=float(props["f_res_hz"]), zeta=run_zeta(props))
    d = observed(model, T, run) / run.T
    db, deg = 20 * np.log10(np.abs(d)), np.degrees(np.angle(d))
    sdb, sdeg = scale_arrays(None)
    return db, deg, float(np.sqrt((np.mean((db / sdb[0]) ** 2) + np.mean((deg / sdeg[0]) ** 2)) / 2))


FLOOR = {0.5: 0.5, 2.0: 0.5, 10.0: 8.0}  # E bounds of the complex drive (measured 0.01, 0.07-0.09, 4.6-6.6)


@pytest.mark.parametrize("joint", ["linear", "iwan"])
@pytest.mark.parametrize("eta", [0.5, 2.0, 10.0])
def test_the_fast_model_follows_an_open_loop_force(joint, eta):
    """The fast model under the measured force's complex envelope against the time simulation of the same model:
    E below 0.5 up to eta 2 (the frame-by-frame magnitude alone misses by E 0.6 at eta 0.5 and 4.3-4.4 at eta 2:
    at least 4x more there); at eta 10 the stated floor, the force ringing inside one window of the envelopes."""
    model = _joint(joint)
    rec, row = _force_record(model, eta)
    env, _, props = measure_run(simulate_record(model, rec, row), row)
    run = run_envelope(env, {**row, **props}, *scale_arrays(None))
    assert run.drive is not None and run.drive.phase_rad is not None
    assert run.drive.base_g.min() < 0.3 * run.drive.base_g.max()  # the force dips at the resonance
    db, deg, E = _errors(model, run, props, run.drive)
    _, _, E_mag = _errors(model, run, props, replace(run.drive, phase_rad=None))  # the drive's magnitude only
    print(f"{joint} eta {eta} (read {props['eta']:.2f}): E {E:.2f} ({np.sqrt(np.mean(db**2)):.4f} dB, "
          f"{np.sqrt(np.mean(deg**2)):.3f} deg rms; max {np.max(np.abs(db)):.3f} dB, {np.max(np.abs(deg)):.2f} deg); "
          f"magnitude only E {E_mag:.2f}")
    assert E < FLOOR[eta], (joint, eta, E)
    if eta == 2.0:
        assert E_mag > 4 * E, (E_mag, E)
