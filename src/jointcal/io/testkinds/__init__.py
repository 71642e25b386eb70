"""Test kinds: the ways a run was measured (the manifest's ``test``), one module each, one registry.

A kind is its contract row here, in `jointcal.io` (the bottom layer: its manifest columns, its
checks, how its record is read), and its read-out rule one layer up, in `jointcal.measure.testkinds`
(an ordered tuple of estimators, each returning a read-out or a refusal with its reason), registered
under the same name. The split follows the layers: the read-out needs the spectral and modal
estimators of `jointcal.measure`, which import io; one registry spanning both would import upwards.
The stages above (calibrate, validate, discrepancy, report) ask the kind (`run_test_kind(row).swept`,
`swept_mask`) or its read-out's estimators, not its name; `jointcal.synth` plans each kind's runs
(`jointcal.synth.campaign.PLANS`).

=========  ==============  ===============================================================================
kind       needs           what the record holds
=========  ==============  ===============================================================================
sweep      direction,      a linear sine sweep (the default: the ``test`` column absent or the cell empty,
           f_start_hz,     exactly the contract before kinds); read through its envelopes
           f_stop_hz,      (`jointcal.measure.modal.READOUT_RULE`)
           sweep_rate_..
dwell      dwell_hz        a steady sine at ``dwell_hz``, possibly followed by its ring-down after the cut
ringdown   -               a free decay, after an impact or a drive cut off
=========  ==============  ===============================================================================

How to add a test kind:

1. Write ``jointcal/io/testkinds/<name>.py`` holding ``KIND = TestKind(name, needs, what, row, ...)``
   (`kind.TestKind`: its manifest columns, its row's checks, the band its drive is checked over or
   why none, whether a lab export may lack its reference); import it and ``register`` it below.
2. Write its read-out rule, ``jointcal/measure/testkinds/<name>.py`` (`jointcal.measure.testkinds`).
3. Plan its virtual-lab runs (``jointcal.synth.campaign.PLANS``), and add its row to
   raw_data/README.md's *Test kinds* and to the table above.
"""
from . import dwell, ringdown, sweep
from .dwell import DWELL
from .kind import TestKind
from .registry import (DEFAULT, TEST, TEST_KINDS, is_swept, kind_columns, manifest_kind, register, run_test_kind,
                       swept_mask, test_kind)
from .sweep import SWEEP_ONLY

for _module in (sweep, dwell, ringdown):
    register(_module.KIND)

__all__ = ["TestKind", "TEST_KINDS", "TEST", "DEFAULT", "DWELL", "SWEEP_ONLY", "register", "manifest_kind",
           "run_test_kind", "test_kind", "is_swept", "swept_mask", "kind_columns"]
