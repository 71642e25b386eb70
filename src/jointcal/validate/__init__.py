"""Validation (the paper's section 3.3.3, Fig. 3.11): the calibrated model driven by each run's
measured base record, through the same envelopes and modal chain as the measurement; a dwell's steady
point and a ring-down's decay (from the record's state at the cut-off) through the same read-outs
(`jointcal.validate.testkinds`)."""
from .assembly import ValidateSettings, Validation, validate_runs
from .error import describe_misfit, envelope_error, repeat_scatter
from .models import model_from_best, model_from_params, models_from_samples
from .runs import band_frames, clean_base, compare_run, draw_transmissibility, measure_pair, simulate_record
from .testkinds import validate_test_run

__all__ = ["ValidateSettings", "Validation", "validate_runs", "describe_misfit", "envelope_error", "repeat_scatter",
           "model_from_best", "model_from_params", "models_from_samples", "band_frames", "clean_base", "compare_run",
           "draw_transmissibility", "measure_pair", "simulate_record", "validate_test_run"]
