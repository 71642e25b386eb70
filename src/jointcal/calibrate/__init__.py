"""Calibration stage: a GA (DEAP) on the paper's eq. 3.9, per assembly.

Modules in the order data flows: `data` (the modal stage's tables -> `ModalData`; `_readouts`: a ring-down's and a
level's dwells' points and weights),
`kind` (what the model is: the Ministack, or one mode of any structure, and its bounds),
`space` (bounds and the GA's unit cube), `objective` (eq. 3.9, vectorised over a
population), `ga` (DEAP loop with stall stop and checkpoints), `fit` (GA + polish ->
tables), `settings` (the ``calibrate:`` config section) and `stage` (files).
"""
from .data import DAMPING, CalibrationInputError, ModalData, read_backbone, read_modal, read_table, select_modal
from .fit import Calibration, calibrate, least_squares_polish, model_curves, polish, polish_starts, search
from .ga import GAOptions, GAResult, run_ga
from .kind import KINDS, data_bounds, excitation_of_table, kind_of, model_words
from .objective import MODELS, PENALTY, objective, predict
from .settings import DEFAULT_BOUNDS, CalibrateSettings
from .space import LOG_SCALED, PARAMS, UNITS, ParamSpace
from .stage import OUTPUTS, resolve, run_calibration

__all__ = [
    "CalibrationInputError", "ModalData", "DAMPING", "read_modal", "read_table", "read_backbone", "select_modal",
    "ParamSpace", "PARAMS", "UNITS", "LOG_SCALED",
    "MODELS", "PENALTY", "predict", "objective",
    "GAOptions", "GAResult", "run_ga",
    "Calibration", "calibrate", "search", "polish", "least_squares_polish", "polish_starts", "model_curves",
    "CalibrateSettings", "DEFAULT_BOUNDS",
    "OUTPUTS", "resolve", "run_calibration",
    "KINDS", "data_bounds", "excitation_of_table", "kind_of", "model_words",
]
