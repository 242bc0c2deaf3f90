"""The closed loop: the plant stepped sample by sample (10 ms) with a controller in the loop.

Order within a sample k: the sensors read the motor A speed and the pump speed at t_k (with the
test bed's noise), the controller computes the coil command, the plant integrates over
[t_k, t_k+1) with that command held (:class:`hwpts.plant.PlantStepper`). The loop starts in the
steady state at the first set-point (the plant's own steady-state inverse gives the valve
command), and every controller starts bumplessly there.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass

import numpy as np

from hwpts.control.controllers.reference import ReferenceController, SteadyStateInverse
from hwpts.control.scenarios import Scenario
from hwpts.plant import PlantStepper
from hwpts.plant.testbed import DEFAULT_NOISE_STD_RPM

REACHABLE_HOLD_S = 2.0
"""A sample counts as reachable time when the set-point has been within the plant's steady-state
reach (valve fully open) at the present pump speed command for at least this long [s]."""


@dataclass
class LoopResult:
    """One controller on one scenario: signals on the loop's grid and the controller's timing."""

    controller: str
    columns: dict
    step_time_ms: np.ndarray

    def __getitem__(self, key):
        return self.columns[key]


def reachable_mask(scenario: Scenario, speed_table=None) -> np.ndarray:
    """Samples where the set-point is within reach (see :data:`REACHABLE_HOLD_S`)."""
    params = scenario.parameters
    out = np.zeros(scenario.time.size, dtype=bool)
    pumps = np.arange(0.0, 1301.0, 10.0)
    for factor in np.unique(scenario.load_factor):
        p = params.replace(motor_a_load_torque=params.motor_a_load_torque * factor,
                           generator_slip_gain=params.generator_slip_gain * factor)
        table = SteadyStateInverse.speed_table(p) if (speed_table is None or factor != 1.0) else speed_table
        top = table.max(axis=0)
        rows = scenario.load_factor == factor
        out[rows] = np.interp(scenario.pump_command_rpm[rows], pumps, top) >= scenario.setpoint_rpm[rows]
    hold = int(round(REACHABLE_HOLD_S / (scenario.time[1] - scenario.time[0])))
    run = np.zeros(out.size, dtype=np.int64)
    count = hold + 1  # the loop starts in steady state
    for k, ok in enumerate(out):
        count = count + 1 if ok else 0
        run[k] = count
    return run > hold


def initial_command(scenario: Scenario) -> float:
    """The valve command holding the first set-point at the first pump speed (plant's own map)."""
    u, _ = SteadyStateInverse(scenario.parameters, scenario.setpoint)(float(scenario.pump_command_rpm[0]))
    return 1.2 if not math.isfinite(u) else u


def run_loop(scenario: Scenario, controller, seed: int = 0, noise_std_rpm: float = DEFAULT_NOISE_STD_RPM,
             reachable=None, progress=None) -> LoopResult:
    """Run ``controller`` on ``scenario``; sensor noise drawn from ``seed``."""
    t = scenario.time
    n = t.size
    dt = float(t[1] - t[0])
    rng = np.random.default_rng(seed)
    noise = noise_std_rpm * rng.standard_normal((2, n))
    v0 = initial_command(scenario)
    plant = PlantStepper(scenario.parameters, dt, v0, float(scenario.pump_command_rpm[0]))
    cols = {k: np.empty(n) for k in ("motor_a_speed_rpm", "motor_a_speed_measured_rpm", "pump_speed_rpm",
                                     "valve_command_v", "valve_effective_v", "valve_compensated_v", "region")}
    steps = np.empty(n)
    knows_pump = isinstance(controller, ReferenceController)
    speed0 = plant.motor_a_speed_rpm
    pump0 = plant.pump_speed_rpm(scenario.pump_command_rpm[0])
    if knows_pump:
        controller.set_pump_command(scenario.pump_command_rpm[0])
    controller.reset(scenario.setpoint, speed0 + noise[1, 0], pump0 + noise[0, 0], v0)
    sp = scenario.setpoint_rpm
    wcmd = scenario.pump_command_rpm
    load = scenario.load_factor
    clock = _time.perf_counter_ns
    every = max(1, n // 100)
    for k in range(n):
        if load[k] != plant.load_factor:
            plant.set_load_factor(load[k])
        speed = plant.motor_a_speed_rpm
        pump = plant.pump_speed_rpm(wcmd[k])
        ym = speed + noise[1, k]
        pm = pump + noise[0, k]
        if knows_pump:
            controller.set_pump_command(wcmd[k])
        t0 = clock()
        u = controller.step(sp[k], ym, pm)
        steps[k] = (clock() - t0) * 1e-6
        cols["motor_a_speed_rpm"][k] = speed
        cols["motor_a_speed_measured_rpm"][k] = ym
        cols["pump_speed_rpm"][k] = pump
        cols["valve_command_v"][k] = u
        cols["valve_compensated_v"][k] = controller.effective
        cols["region"][k] = controller.region + 1  # 1-based as in the model file and summary; 0: no region (pi)
        plant.step(u, wcmd[k])
        cols["valve_effective_v"][k] = plant.effective_voltage_v
        if progress is not None and k % every == 0:
            progress(k / n)
    columns = {"time_s": t, "setpoint_rpm": sp, "pump_speed_command_rpm": wcmd, "load_factor": load, **cols}
    columns["reachable"] = (reachable_mask(scenario) if reachable is None else reachable).astype(float)
    return LoopResult(controller.name, columns, steps)
