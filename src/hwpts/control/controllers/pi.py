"""``pi``: the baseline. One PI law tuned from the model bank at the nominal operating point, with
anti-windup and a steady-state set-point feedforward."""

from __future__ import annotations

import math

from hwpts.control.controllers.base import Controller, HysteresisInverse, LowPass, PIGains, PILaw
from hwpts.control.model import ModelBank
from hwpts.errors import DataError

CLOSED_LOOP_TIME_S = 0.05
"""tau_c of the SIMC rule for the baseline [s]: the best of 0.05, 0.08, 0.10 and 0.15 s on class A
turbulence (RMS error 0.62, 0.76, 0.85, 1.08 % over 200 s), so the baseline is a tuned one."""

NOMINAL_PUMP_RPM = 700.0
"""The pump speed the baseline's gains and feedforward are designed at [r/min]."""

SPEED_FILTER_S = 0.02
"""Low-pass on the measured speed against sensor noise [s]."""


class UnreachableSetpoint(DataError):
    """The model bank has no steady state at the set-point (the command line names ``--setpoint``)."""


def nominal_design(bank: ModelBank, setpoint: float, pump: float):
    """(region, feedforward voltage) of the model's steady state at the nominal operating point."""
    u, region = bank.steady_valve(setpoint, pump)
    if region is None:
        raise UnreachableSetpoint(f"the model has no steady state at {setpoint:g} r/min with the pump at {pump:g} "
                                  f"r/min; choose a reachable set-point")
    return region, float(u)


def region_gains(bank: ModelBank, region: int, closed_loop_time: float) -> PIGains:
    """SIMC-tuned PI gains for region ``region`` of the model bank, for the closed-loop time constant ``closed_loop_time`` [s]."""
    d = bank.designs[region]
    tau = d.time_constant_s if math.isfinite(d.time_constant_s) else bank.sample_time
    theta = d.dead_time_s if math.isfinite(d.dead_time_s) else 0.0
    # the loop runs faster than the model: half a model sample stands for the block-mean delay
    return PIGains.simc(d.valve_gain_rpm_per_v, tau, theta + 0.5 * bank.sample_time, closed_loop_time)


class PIController(Controller):
    """PI on the effective valve voltage, gains by SIMC from the region of the nominal operating point;
    the feedforward is that region's steady-state valve voltage for the set-point at the nominal pump
    speed (recomputed when the set-point changes)."""

    name = "pi"

    def __init__(self, bank: ModelBank, half_width: float, inverse: bool = True,
                 nominal_pump: float = NOMINAL_PUMP_RPM,
                 sample_time: float = 0.01, closed_loop_time: float = CLOSED_LOOP_TIME_S):
        super().__init__(sample_time)
        self.bank = bank
        self.nominal_pump = float(nominal_pump)
        self.inverse = HysteresisInverse(half_width, inverse)
        self.closed_loop_time = closed_loop_time
        self.speed_filter = LowPass(SPEED_FILTER_S, sample_time)
        self._setpoint = math.nan
        self.law = None
        self.feedforward = math.nan

    @property
    def effective(self) -> float:
        """The valve voltage [V] after the hysteresis inverse."""
        return self.inverse.effective

    def _design(self, setpoint):
        region, ff = nominal_design(self.bank, setpoint, self.nominal_pump)
        self.feedforward = ff
        gains = region_gains(self.bank, region, self.closed_loop_time)
        if self.law is None:
            self.law = PILaw(gains, self.sample_time, self.inverse.effective_limits)
        self._setpoint = setpoint

    def reset(self, setpoint, speed, pump, command):
        """Start without a bump: the integrator holds ``command`` minus the feedforward."""
        self.inverse.reset(command)
        self.speed_filter.reset(speed)
        self._design(setpoint)
        self.law.reset_to(command, self.feedforward, setpoint - speed)

    def step(self, setpoint, speed, pump):
        """One 10 ms sample of the PI law with anti-windup and set-point feedforward; returns the valve command [V]."""
        if setpoint != self._setpoint:
            self._design(setpoint)
        y = self.speed_filter(speed)
        desired = self.law(setpoint - y, self.feedforward)
        return self.inverse(desired)
