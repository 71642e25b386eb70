"""The fast model's floor (jointcal.discrepancy.floor) for one mode of any structure,
driven by a force or a voltage (issue 30): the swept envelope of every modal-library effect against the exact time
simulation of the same model.

Oracles: the time simulation of the same model (`jointcal.validate.drive.simulate_record`, the exact Iwan joint
integrated with its elements, the neighbouring mode applied to the record's spectrum), measured by the modal stage."""
from __future__ import annotations

import numpy as np
import pytest

from jointcal.discrepancy.data import run_envelope, run_zeta, scale_arrays
from jointcal.discrepancy.fit import observed
from jointcal.effects import EFFECTS, apply_effect, library
from jointcal.measure.modal import measure_run
from jointcal.models import MinistackModel, swept_transmissibility
from jointcal.validate.drive import simulate_record
from tests._support.beam_runs import BEAM, _run


def _fast_against_time(model: MinistackModel, ref: str, level: float) -> tuple[np.ndarray, np.ndarray]:
    """dB and degree errors of the fast model's envelope against the time simulation of the same model, at the
    frames the discrepancy fits use."""
    rec, row = _run(ref, level)
    sim = simulate_record(model, rec, row)
    env, _, props = measure_run(sim, row)
    run = run_envelope(env, {**row, **props}, *scale_arrays(None))
    T = swept_transmissibility(model, run.drive, run.t_s, f_res_hz=float(props["f_res_hz"]), zeta=run_zeta(props))
    d = observed(model, T, run) / run.T
    return 20 * np.log10(np.abs(d)), np.degrees(np.angle(d))


# each effect at a strength the beam shows (the library's hidden defaults are the Ministack's)
ON_BEAM = {"channel_delay": {"tau_s": 4e-4},  # 14 deg at the mode
           "cubic_stiffening": {"k3": 3e5},  # 3/4 k3 q^2 ~ 4% of k + KT at the top of the run
           "joint_settling": {"Fs_drift": 0.15, "KT_drift": 0.1, "n_settle": 3.0}}


@pytest.mark.parametrize("ref,level", [("force", 0.4), ("voltage", 0.2)])  # q about 0.01 in, eta about 1
@pytest.mark.parametrize("effect", ["baseline", *library("modal")])
def test_the_fast_model_of_one_driven_mode_is_its_time_simulation(ref, level, effect):
    """Every modal-library effect, a force and a steeply sloped voltage gain: the swept envelope under the
    equivalent base drive against the exact time simulation of the same model. Its error, in the validation's
    E over the smallest repeat scatter the stage admits (0.05 dB, 0.3 deg: `scale_arrays`' floors), stays
    below 0.5: the floor each diagnosis states is this on the calibrated model."""
    values = ON_BEAM.get(effect, EFFECTS[effect].defaults if effect != "baseline" else {})
    model = BEAM if effect == "baseline" else apply_effect(BEAM, effect, values, {"sequence": 4})
    db, deg = _fast_against_time(model, ref, level)
    sdb, sdeg = scale_arrays(None)
    E = np.sqrt((np.mean((db / sdb[0]) ** 2) + np.mean((deg / sdeg[0]) ** 2)) / 2)
    print(f"{effect} {ref}: {np.sqrt(np.mean(db**2)):.4f} dB, {np.sqrt(np.mean(deg**2)):.3f} deg rms, E {E:.2f}")
    assert E < 0.5, (effect, ref, E)
