"""What a run's record says about the mode: envelopes, read-outs, FRF, swept-mode fit, scatter.

Modules, in the order a record flows through them:

* `envelopes`: the drive-frequency ridge and the complex envelopes of every channel.
* `frf` (with `modefit` and `backbone`): the whole-record FRF, its single-mode fit, and
  a voltage-driven peak's equal-amplitude line pairs.
* `sweepfit` (with `_rotating` and `_sweep_problem`): one amplitude-dependent mode fitted
  to a swept run's whole transient.
* `modal` (with `_envelope_readout` and `_excited`): resonance, damping and amplitude of
  one run, by one read-out rule (`readout_rule`); `measure_run` chains envelopes -> modal.
* `scatter`: the read-outs' spread across repeats and up/down pairs.
* `_peaks`: the small read-outs they share (peak parabola, half-power, quadrature
  crossing, full-drive frames, transmissibility).
"""
from __future__ import annotations

from .envelopes import EnvelopeMeta, envelopes, meta_dict, track_drive, window_length
from .backbone import backbone_at_peak, pair_backbone
from .frf import ModeFit, displacement_ratio, fit_mode, frf_table, h1_estimate, record_frf, zeta_at_quadrature
from .sweepfit import SweepFit, baseband, fit_swept_mode
from .modal import ENVELOPE_COLUMNS, FLAG_WORDS, measure_run, modal_properties, readout_rule
from ._excited import band_envelope_peak
from ._peaks import full_drive, transmissibility
from .scatter import scatter

__all__ = [
    "EnvelopeMeta", "envelopes", "meta_dict", "track_drive", "window_length",
    "ModeFit", "h1_estimate", "displacement_ratio", "fit_mode", "zeta_at_quadrature", "record_frf", "frf_table",
    "pair_backbone", "backbone_at_peak", "SweepFit", "baseband", "fit_swept_mode",
    "modal_properties", "measure_run", "readout_rule", "band_envelope_peak", "FLAG_WORDS", "ENVELOPE_COLUMNS",
    "full_drive", "transmissibility", "scatter",
]
