"""Joint and structure models: exact Iwan, QSMA, harmonic balance, swept-sine simulator."""
from .amplitude import G, harmonic_balance, jenkins_inphase, population_curves, qsma, resonance_amplitude
from .iwan import IwanParams, backbone, backbone_stiffness, derived, dissipation, force_history
from .elements import Element, contact_spring, cubic_spring, quadratic_damper
from .simulate import SimResult, fractional_delay, integrate, simulate
from .structure import Fixture, MinistackModel, Neighbour, state_space
from .envelope import SteadyState, steady_state
from .swept import SweepDrive, quasi_steady
from .swept_integrated import swept_transmissibility

__all__ = [
    "G", "IwanParams", "derived", "backbone", "backbone_stiffness", "dissipation", "force_history",
    "qsma", "harmonic_balance", "jenkins_inphase", "population_curves", "resonance_amplitude",
    "MinistackModel", "Fixture", "Neighbour", "SteadyState", "steady_state", "SweepDrive", "quasi_steady", "swept_transmissibility",
    "state_space", "simulate", "integrate", "SimResult", "fractional_delay",
    "Element", "cubic_spring", "quadratic_damper", "contact_spring",
]
