"""Speed controllers, chosen by name (a contract: ``hwpts control run --controllers a,b,...``).

Every model-based controller is designed from a PWARX model bank (:class:`hwpts.control.model.ModelBank`),
never from the plant's equations; ``reference`` knows the plant. ``<name>-no-inverse`` is ``<name>``
without the hysteresis inverse.
"""

from __future__ import annotations

from hwpts.control.controllers.base import Controller, HysteresisInverse, PIGains, PILaw
from hwpts.control.controllers.hybrid_mpc import HybridMPCController
from hwpts.control.controllers.mpc import MPCController
from hwpts.control.controllers.pi import PIController
from hwpts.control.controllers.reference import ReferenceController
from hwpts.control.controllers.scheduled import MMACController, ScheduledController
from hwpts.errors import ParameterError

BASE_NAMES = ("pi", "scheduled", "mmac", "mpc", "hybrid-mpc", "reference")
CONTROLLER_NAMES = tuple(n for b in BASE_NAMES for n in (b, f"{b}-no-inverse"))
MODEL_BASED = ("pi", "scheduled", "mmac", "mpc", "hybrid-mpc")
AVAILABLE = BASE_NAMES
"""Base names implemented so far."""

_CLASSES = {"pi": PIController, "scheduled": ScheduledController, "mmac": MMACController, "mpc": MPCController,
            "hybrid-mpc": HybridMPCController}


def parse_names(text: str) -> list[str]:
    """'a,b,...' -> names, each checked against the registry."""
    names = [n.strip() for n in str(text).split(",")]
    if not any(names):
        raise ParameterError("--controllers: expected a comma-separated list of controller names, got an empty list")
    if not all(names):  # 'pi,,mpc' or 'pi,': a name left out by mistake, not nothing
        raise ParameterError(f"--controllers: an empty name in {text!r}; expected names separated by single commas")
    for n in names:
        if n not in CONTROLLER_NAMES:
            raise ParameterError(f"--controllers: unknown controller {n!r}; expected names from "
                                 f"{', '.join(CONTROLLER_NAMES)}")
        if n.removesuffix("-no-inverse") not in AVAILABLE:
            raise ParameterError(f"--controllers: {n!r} is not implemented yet; available: "
                                 f"{', '.join(a + s for a in AVAILABLE for s in ('', '-no-inverse'))}")
    if len(set(names)) != len(names):
        raise ParameterError(f"--controllers: a name is given twice in {text!r}")
    return names


def make_controller(name: str, bank, half_width: float, scenario, sample_time: float = 0.01) -> Controller:
    """The controller ``name`` for a scenario (its set-points; the reference also its plant)."""
    base = name.removesuffix("-no-inverse")
    inverse = not name.endswith("-no-inverse")
    if base == "reference":
        c = ReferenceController(scenario.parameters, scenario.setpoint_rpm, inverse, sample_time)
    else:
        c = _CLASSES[base](bank, half_width, inverse, sample_time=sample_time)
    c.name = name
    return c


__all__ = ["AVAILABLE", "BASE_NAMES", "CONTROLLER_NAMES", "MODEL_BASED", "Controller", "HybridMPCController", "HysteresisInverse",
           "MMACController", "MPCController", "PIController", "PIGains", "PILaw", "ReferenceController", "ScheduledController",
           "make_controller", "parse_names"]
