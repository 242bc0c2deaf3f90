"""The closed-loop scenarios (names are a contract: ``hwpts control run --scenario NAME``).

Each scenario is a set of signals on the 10 ms grid: the speed set-point, the pump (turbine
emulator) speed command, the electric load factor on shaft A, and the times of the events a metric
measures a response to. The test bed is :meth:`PlantParameters.test_bed` (hysteresis, droop) with
the induction generator option on (:data:`GENERATOR_SLIP_GAIN`) and 2 r/min sensor noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hwpts.control.wind import Turbine, kaimal_wind
from hwpts.errors import ParameterError
from hwpts.plant import PlantParameters

SAMPLE_TIME_S = 0.01
"""The control loop's period [s] (the test bed's logger period)."""

SETPOINT_RPM = 1000.0
"""The generator's synchronous speed, the default set-point [r/min] (paper section I)."""

GENERATOR_SLIP_GAIN = 0.005
"""K_g of the induction generator on shaft A [N m s/rad] (assumed): 0.05 N m, 5 % of the 1 N m
electric load, per 100 r/min of slip. Small, so the model bank identified without it still fits."""

NOMINAL_PUMP_RPM = 950.0
"""Pump speed command of the step scenarios [r/min]: +-200 r/min keeps 1000 r/min reachable."""

TURBULENCE_MEAN_WIND = 9.5
"""Mean wind of the turbulence scenarios [m/s]: the turbine runs the pump at 889 r/min (600-1000 r/min
most of the time; class A dips below the reachable 710 r/min now and then)."""

SCENARIO_NAMES = ("setpoint-step", "pump-step", "load-step", "turbulence-a", "turbulence-b", "turbulence-c", "low-wind")


@dataclass
class Scenario:
    name: str
    description: str
    time: np.ndarray
    setpoint_rpm: np.ndarray
    pump_command_rpm: np.ndarray
    load_factor: np.ndarray
    kind: str
    """'setpoint' (settling and overshoot apply), 'disturbance' (peak deviation and recovery apply),
    'turbulence' or 'low-wind'."""
    events_s: tuple = ()
    wind_m_s: np.ndarray | None = None
    parameters: PlantParameters = field(default_factory=lambda: test_bed_with_generator())

    @property
    def setpoint(self) -> float:
        """The initial set-point [r/min]."""
        return float(self.setpoint_rpm[0])


def test_bed_with_generator() -> PlantParameters:
    """The test bed (hysteresis, droop) with the induction generator load on shaft A."""
    return PlantParameters.test_bed().replace(generator_slip_gain=GENERATOR_SLIP_GAIN,
                                              generator_synchronous_speed=SETPOINT_RPM * math.pi / 30.0)


DEFAULT_DURATION_S = {"setpoint-step": 20.0, "pump-step": 32.0, "load-step": 32.0, "turbulence": 600.0, "low-wind": 60.0}
"""Each scenario's own record length [s] (the turbulence scenarios share one)."""


def scenario_duration(name: str, duration: float | None = None) -> float:
    """The record length [s] scenario ``name`` runs for: ``duration`` on the sample grid, or its own."""
    own = DEFAULT_DURATION_S["turbulence" if name.startswith("turbulence-") else name]
    return float(_grid(duration or own)[-1])


def _grid(duration):
    return np.arange(int(round(duration / SAMPLE_TIME_S)) + 1) * SAMPLE_TIME_S


def _steps(t, base, changes):
    out = np.full(t.size, float(base))
    for at, value in changes:
        out[t >= at - 1e-9] = value
    return out


def build_scenario(name: str, seed: int = 0, setpoint: float = SETPOINT_RPM, duration: float | None = None) -> Scenario:
    """The scenario ``name`` (one of :data:`SCENARIO_NAMES`) for a set-point and a seed."""
    if name not in SCENARIO_NAMES:
        raise ParameterError(f"unknown scenario {name!r}; expected one of {', '.join(SCENARIO_NAMES)}")
    turbine = Turbine()
    if name == "setpoint-step":
        t = _grid(duration or DEFAULT_DURATION_S["setpoint-step"])
        sp = _steps(t, setpoint, [(4.0, setpoint * 1.05), (12.0, setpoint)])
        return Scenario(name, f"set-point steps {setpoint:g} -> {setpoint * 1.05:g} -> {setpoint:g} r/min at 4 s and "
                              f"12 s, pump at {NOMINAL_PUMP_RPM:g} r/min", t, sp, np.full(t.size, NOMINAL_PUMP_RPM),
                        np.ones(t.size), "setpoint", (4.0, 12.0))
    if name == "pump-step":
        t = _grid(duration or DEFAULT_DURATION_S["pump-step"])
        w = _steps(t, NOMINAL_PUMP_RPM, [(4.0, NOMINAL_PUMP_RPM + 200), (11.0, NOMINAL_PUMP_RPM),
                                         (18.0, NOMINAL_PUMP_RPM - 200), (25.0, NOMINAL_PUMP_RPM)])
        return Scenario(name, f"pump-speed command steps of +-200 r/min about {NOMINAL_PUMP_RPM:g} r/min every 7 s",
                        t, np.full(t.size, setpoint), w, np.ones(t.size), "disturbance", (4.0, 11.0, 18.0, 25.0))
    if name == "load-step":
        t = _grid(duration or DEFAULT_DURATION_S["load-step"])
        load = _steps(t, 1.0, [(4.0, 1.3), (11.0, 1.0), (18.0, 0.7), (25.0, 1.0)])
        return Scenario(name, "electric load steps of +30 % and -30 % on the generator (shaft A) every 7 s, pump at "
                              f"{NOMINAL_PUMP_RPM:g} r/min", t, np.full(t.size, setpoint), np.full(t.size, NOMINAL_PUMP_RPM),
                        load, "disturbance", (4.0, 11.0, 18.0, 25.0))
    if name.startswith("turbulence-"):
        cls = name[-1].upper()
        t = _grid(duration or DEFAULT_DURATION_S["turbulence"])
        wind = kaimal_wind(t[-1], SAMPLE_TIME_S, TURBULENCE_MEAN_WIND, cls, seed=seed)
        w = turbine.pump_speed_command(wind, SAMPLE_TIME_S)
        return Scenario(name, f"IEC 61400-1 class {cls} turbulence (Kaimal), mean wind {TURBULENCE_MEAN_WIND:g} m/s, "
                              f"{t[-1]:g} s, seed {seed}", t, np.full(t.size, setpoint), w, np.ones(t.size), "turbulence",
                        (), wind)
    # low-wind: the wind falls until 1000 r/min is out of reach, stays low, and comes back
    t = _grid(duration or DEFAULT_DURATION_S["low-wind"])
    v_hi = TURBULENCE_MEAN_WIND
    v_lo = 6.0
    wind = np.interp(t, [0, 8, 14, 34, 40, t[-1]], [v_hi, v_hi, v_lo, v_lo, v_hi, v_hi])
    w = turbine.pump_speed_command(wind, SAMPLE_TIME_S)
    return Scenario(name, f"wind ramps {v_hi:g} -> {v_lo:g} m/s (8-14 s), stays low (set-point out of reach) and "
                          f"returns (34-40 s)", t, np.full(t.size, setpoint), w, np.ones(t.size), "low-wind",
                    (34.0,), wind)
