"""What a run's record says about the mode: envelopes, read-outs, FRF, swept-mode fit, scatter.

Modules, in the order a record flows through them (import from the module: this
``__init__`` imports none of them, so that a workflow stage's code hash,
`jointcal._workflow.stage_hash`, holds only the modules the stage runs):

* `envelopes`: the drive-frequency ridge and the complex envelopes of every channel.
* `frf` (with `modefit` and `backbone`): the whole-record FRF, its single-mode fit, and
  a voltage-driven peak's equal-amplitude line pairs.
* `sweepfit` (with `_rotating` and `_sweep_problem`): one amplitude-dependent mode fitted
  to a swept run's whole transient.
* `modal` (with `_envelope_readout` and `_excited`): resonance, damping and amplitude of
  one run, by one read-out rule (`modal.READOUT_RULE`); `modal.measure_run` chains
  envelopes -> modal.
* `testkinds` (with `ringdown`, `forced_decay`, `dwell`, `receptance`): the runs of the test kinds
  that are not swept (`jointcal.io.testkinds`), each read by its kind's registered rule, an ordered
  tuple of estimators (`testkinds.read` reads the record; backbone.csv).
* `scatter`: the read-outs' spread across repeats and up/down pairs.
* `peaks`: the small read-outs they and other stages share (half-power, quadrature
  crossing, full-drive frames, transmissibility); the peak parabola and a record's peak
  frequency, which `jointcal.io` uses too, are in `jointcal.spectral`.
"""
