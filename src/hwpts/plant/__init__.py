"""The simulated HWPTS test bed (docs/plant.md): parameters, valve, dynamics, steady state, simulation."""

from hwpts.plant.dynamics import jacobian, linearize, paper_form, rhs, transfer_poles_zeros
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.profiles import CASE_NAMES, InputProfile, identification_excitation, validation_case
from hwpts.plant.simulate import PlantResponse, PlantStepper, SolverStats, simulate_plant
from hwpts.plant.steady_state import SteadyState, SweepResult, steady_state, sweep
from hwpts.plant.testbed import TestBed
from hwpts.plant.valve import orifice_flow, outlet_areas, play_operator, spool_position

__all__ = [
    "CASE_NAMES",
    "InputProfile",
    "PlantParameters",
    "PlantResponse",
    "PlantStepper",
    "SolverStats",
    "SteadyState",
    "SweepResult",
    "TestBed",
    "identification_excitation",
    "jacobian",
    "linearize",
    "orifice_flow",
    "outlet_areas",
    "paper_form",
    "play_operator",
    "rhs",
    "simulate_plant",
    "spool_position",
    "steady_state",
    "sweep",
    "transfer_poles_zeros",
    "validation_case",
]
