"""``reference``: a controller that knows the plant (its parameters, the true play width and the
pump speed *command*), to show what is achievable. Not a model-based design: a yardstick."""

from __future__ import annotations

import math

import numpy as np

from hwpts.control.controllers.base import Controller, HysteresisInverse, LowPass, PIGains, PILaw
from hwpts.control.controllers.pi import CLOSED_LOOP_TIME_S, SPEED_FILTER_S
from hwpts.plant import PlantParameters, steady_state


class SteadyStateInverse:
    """The plant's own steady-state map inverted: effective valve voltage giving a motor A speed at a
    pump speed command (tabulated on a grid, on the valve-limited slope of the surface)."""

    def __init__(self, parameters: PlantParameters, setpoint: float, speed=None):
        self.pumps = np.arange(0.0, 1301.0, 10.0)
        volts = np.arange(1.2, 3.5001, 0.01)
        if speed is None:
            speed = self.speed_table(parameters)
        self.table = np.full(self.pumps.size, np.nan)
        self.gain = np.full(self.pumps.size, np.nan)
        for j in range(self.pumps.size):
            s = speed[:, j]
            above = np.nonzero(s >= setpoint)[0]
            if above.size == 0:
                continue
            k = above[-1]  # the last voltage still reaching the set-point: on the slope
            if k + 1 < volts.size:
                frac = (s[k] - setpoint) / max(s[k] - s[k + 1], 1e-9)
                self.table[j] = volts[k] + frac * (volts[k + 1] - volts[k])
                self.gain[j] = (s[k + 1] - s[k]) / (volts[k + 1] - volts[k])
            else:
                self.table[j] = volts[k]
                self.gain[j] = (s[k] - s[k - 1]) / (volts[k] - volts[k - 1])

    @classmethod
    def speed_table(cls, parameters: PlantParameters) -> np.ndarray:
        """Steady motor A speed [r/min] on the (valve, pump command) grid, averaged valve."""
        averaged = parameters.replace(hysteresis_half_width=0.0)
        vv, ww = np.meshgrid(np.arange(1.2, 3.5001, 0.01), np.arange(0.0, 1301.0, 10.0), indexing="ij")
        return steady_state(averaged, vv, ww).motor_a_speed_rpm

    def __call__(self, pump_command: float) -> tuple[float, float]:
        ok = np.isfinite(self.table)
        if not ok.any() or pump_command < self.pumps[ok][0]:
            return math.nan, math.nan
        return (float(np.interp(pump_command, self.pumps[ok], self.table[ok])),
                float(np.interp(pump_command, self.pumps[ok], self.gain[ok])))


class ReferenceController(Controller):
    """Feedforward from the plant's exact steady-state inverse at the pump speed command, the exact
    play inverse, and PI feedback tuned on the plant's own slope (t63 0.25 s of the valve step)."""

    name = "reference"

    def __init__(self, parameters: PlantParameters, setpoints, inverse: bool = True, sample_time: float = 0.01):
        super().__init__(sample_time)
        self.parameters = parameters
        self.inverse = HysteresisInverse(parameters.hysteresis_half_width, inverse)
        table = SteadyStateInverse.speed_table(parameters)
        self.maps = {float(s): SteadyStateInverse(parameters, float(s), table) for s in np.unique(setpoints)}
        self.setpoint = float(np.asarray(setpoints).ravel()[0])
        self.map = self.maps[self.setpoint]
        _, gain = self.map(1000.0)
        self.law = PILaw(PIGains.simc(gain, 0.25, 0.02, CLOSED_LOOP_TIME_S), sample_time, self.inverse.effective_limits)
        self.speed_filter = LowPass(SPEED_FILTER_S, sample_time)
        self.pump_command = math.nan
        self.feedforward = math.nan

    @property
    def effective(self) -> float:
        """The valve voltage [V] after the hysteresis inverse."""
        return self.inverse.effective

    def set_pump_command(self, pump_command: float) -> None:
        """The reference is told the pump speed command (it knows the plant and its inputs)."""
        self.pump_command = float(pump_command)

    def _ff(self, pump):
        u, _ = self.map(self.pump_command if math.isfinite(self.pump_command) else pump)
        return self.inverse.effective_limits[0] if not math.isfinite(u) else u

    def reset(self, setpoint, speed, pump, command):
        """Start without a bump from the plant's own steady-state map at the present pump speed."""
        self.inverse.reset(command)
        self.speed_filter.reset(speed)
        self.feedforward = self._ff(pump)
        self.law.reset_to(command, self.feedforward, setpoint - speed)

    def step(self, setpoint, speed, pump):
        """One 10 ms sample: the plant's steady-state inverse as feedforward plus a PI correction; returns the valve command [V]."""
        if setpoint != self.setpoint:
            if setpoint not in self.maps:
                self.maps[setpoint] = SteadyStateInverse(self.parameters, setpoint)
            self.map = self.maps[setpoint]
            self.setpoint = setpoint
        y = self.speed_filter(speed)
        self.feedforward = self._ff(pump)
        return self.inverse(self.law(setpoint - y, self.feedforward))
