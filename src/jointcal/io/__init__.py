"""Raw-data contract: read and validate a swept-sine campaign; write files atomically.

A campaign folder holds ``manifest.csv`` (one row per run) and one record per run
(``.csv``, ``.csv.gz`` or MATLAB ``.mat``) with the columns ``time_s`` (s),
``base_accel_g`` (g) or, for force-driven tests, ``force_lbf`` (lbf), or, for a
shaker driven open-loop, ``drive_V`` (amplifier voltage, V), and ``response_accel_g``
(g) or ``response_accel_m_s2`` (m/s^2, converted to g on read with `jointcal.units.G_SI`).
A record may also be a lab's own export (UFF 58, NI TDMS, Test.Lab MATLAB) whose channels
the manifest names. ``raw_data/README.md`` states the contract for people; every violation
raises `CampaignError` with one sentence that names the file, the problem and the fix.
File I/O of the package lives here.

Modules, in the order a record flows through them:

* `contract` (public): the contract's names, units and errors; `excitation_kind`, the one rule
  that tells a run's excitation from its columns or its level column.
* `testkinds` (public): the test kinds (the manifest's ``test``: ``sweep``, ``dwell``,
  ``ringdown``), one module each in a registry like `jointcal.effects`: a kind's manifest
  columns, its row's checks, the band its drive is checked over, whether its reference may be
  absent; `run_test_kind(row)` is what the stages ask instead of comparing names.
* `_manifest`: ``manifest.csv``, every row checked (`read_manifest`).
* `_records`: one record, the contract's CSV or MAT (`read_run`), a whole campaign
  (`ingest_campaign`), a manifest file among a rule's inputs (`listed_record`).
* `_lab_formats`: UFF 58, TDMS and Test.Lab exports, units converted to the contract's;
  `_lab_channels` reads each format's channels (a file cut short, a sample interval that
  is not positive), `_lab_units` their units as the format stores them (Test.Lab's MKS,
  UFF 58's exponents and data set 164).
* `_checks`: one record against its manifest row (`validate_run`), with `_time` (the time
  axis), `_band` (the drive's band), `_amplitudes` (swapped channels, level, units; over
  `_windows` of 20 drive cycles), `_transmissibility` (a base-driven response's scale from
  its ratio to the base below resonance), `_dead` (a response that does not follow the
  drive) and `_clipping` (samples at an ADC's full scale).
* `_atomic`: writers that never leave half a file.
"""
from __future__ import annotations

from jointcal.io.contract import CampaignError, CampaignWarning, excitation_kind, level_column, level_unit
from jointcal.io._atomic import write_bytes_atomic, write_csv_atomic, write_json_atomic, write_run
from jointcal.io._checks import UNUSABLE_FLAGS, validate_run
from jointcal.io.testkinds import run_test_kind, test_kind
from jointcal.io._manifest import read_manifest
from jointcal.io._records import ingest_campaign, listed_record, read_run

__all__ = [
    "CampaignError", "CampaignWarning", "excitation_kind", "level_column", "level_unit", "read_manifest", "read_run",
    "validate_run", "ingest_campaign", "listed_record", "write_bytes_atomic", "write_csv_atomic",
    "write_json_atomic", "write_run", "UNUSABLE_FLAGS", "test_kind", "run_test_kind",
]
