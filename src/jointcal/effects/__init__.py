"""Effects: physics a calibrated joint model may be missing, one module each, one registry.

Every stage reads this registry: the virtual lab hides an effect (`jointcal.synth`), the
envelope model and the time simulation see it through the `MinistackModel` it returns,
the discrepancy workflow fits, fingerprints, names and advises on it
(`jointcal.discrepancy`), the config schema lists the library (a test checks).

=====================  ===============================================  ==========================================
effect                 parameters                                       what it is
=====================  ===============================================  ==========================================
sensor_gain            gain (-)                                         response accelerometer sensitivity off
                                                                        (Ministack only: one mode's modal constant
                                                                        absorbs it)
channel_delay          tau_s (s)                                        response channel lags the base channel
fixture_flexibility    f_can_hz (Hz), m_can_ratio (-)                   can/fixture on its own spring below the
                                                                        joint (zeta_can fixed at 1%; Ministack)
cubic_stiffening       k3 (lbf/in^3)                                    k3 z^3 spring beside the joint
quadratic_damping      c2 (lbf s^2/in^2)                                c2 z'|z'| damper (air, foam; Ministack)
joint_settling         Fs_drift (-), KT_drift (-), n_settle (runs)      Fs, KT rise with the run sequence n:
                                                                        X (1 + d (1 - exp(-(n-1)/n_settle)))
elastic_softening      loss_ratio (-)                                   joint force r F_iwan + (1 - r) F_b: its
                                                                        backbone, r of Masing's loss (modal only)
neighbour_mode         f_ratio (-), mode_ratio (-); on voltage sweeps   a linear mode the channel also reads
                       also loop_armature (-), back_emf_share (-),      (modal only); on a voltage drive in the
                       read_gain (-), read_phase (rad)                  shaker's loop, the read-out's constant off
contact_spring         contact_k (lbf/in), gap_in (in)                  a stop beyond a gap (even harmonics);
                                                                        outside the discrepancy library
=====================  ===============================================  ==========================================

How to add an effect, in five lines:

1. Write ``jointcal/effects/<name>.py`` holding ``EFFECT = Effect(name, params, apply, advice,
   fingerprint, hidden=...)`` (`effect.Effect`: parameters with units and bounds; the model it makes).
2. ``apply`` changes a `MinistackModel` field or adds an element (`jointcal.models.elements`);
   a new kind of element adds one inline function to each kernel (`_integrator`, `_envelope_kernel`).
3. Import the module and ``register`` it below (or call ``register`` at run time).
4. Add its name to the ``discrepancy.candidates`` enum of ``workflow/schemas/config.schema.yaml``.
5. Add its row to the table above; synth, the models and the discrepancy workflow then know it.
"""
from . import (channel_delay, contact_spring, cubic_stiffening, elastic_softening, fixture_flexibility, joint_settling,
               neighbour_mode, quadratic_damping, sensor_gain)
from .effect import Effect, EffectParam
from .registry import EFFECTS, JOIN, apply_effect, effects_of, library, register

for _module in (sensor_gain, channel_delay, fixture_flexibility, cubic_stiffening, quadratic_damping, joint_settling,
                elastic_softening, neighbour_mode, contact_spring):
    register(_module.EFFECT)

__all__ = ["Effect", "EffectParam", "EFFECTS", "JOIN", "register", "library", "effects_of", "apply_effect"]
