"""``scheduled`` and ``mmac``: one PI law per region of the model bank, with the region's
steady-state feedforward of the measured pump speed and bumpless transfer between regions.

``scheduled`` puts in charge the region the model's partition (paper eq. 9) assigns to the present
regressor; ``mmac`` (multiple-model adaptive control) runs every region's one-step predictor in
parallel and puts in charge the one with the smallest recent prediction error, the paper's stated
reason for a bank of models (section I).
"""

from __future__ import annotations

import math

from hwpts.control.controllers.base import Controller, HysteresisInverse, LowPass, ModelRateHistory, PILaw
from hwpts.control.controllers.pi import NOMINAL_PUMP_RPM, SPEED_FILTER_S, region_gains
from hwpts.control.controllers.play import AdaptiveInverse, PlayWidthEstimator
from hwpts.control.model import ModelBank

CLOSED_LOOP_TIME_S = 0.08
"""tau_c of the SIMC rule per region [s] (the best of 0.05-0.15 s on class A turbulence)."""

FLAT_GAIN_CAP = 10.0
"""A flat region's proportional gain is capped at this multiple of the stiffest region's."""

PUMP_FILTER_S = 0.05
"""Low-pass on the measured pump speed feeding the feedforward [s]."""


class ScheduledController(Controller):
    """Gain-scheduled PI per region with pump-speed feedforward and bumpless transfer.

    At each region change the new region's integral is set so that the output does not jump
    (``bumpless=False`` keeps each region's own integral, for comparison).
    """

    name = "scheduled"
    has_modes = True

    def __init__(self, bank: ModelBank, half_width: float, inverse: bool = True,
                 nominal_pump: float = NOMINAL_PUMP_RPM,
                 sample_time: float = 0.01, closed_loop_time: float = CLOSED_LOOP_TIME_S, bumpless: bool = True,
                 adapt_width: bool = True):
        super().__init__(sample_time)
        self.bank = bank
        self.inverse = HysteresisInverse(half_width, inverse)
        self.adaptive = AdaptiveInverse(self.inverse, PlayWidthEstimator(bank, half_width, sample_time)
                                        if adapt_width else None)
        self.bumpless = bumpless
        self.nominal_pump = float(nominal_pump)
        lims = self.inverse.effective_limits
        gains = {i: region_gains(bank, i, closed_loop_time) for i in bank.control_regions}
        stiffest = max(gains, key=lambda i: abs(bank.designs[i].valve_gain_rpm_per_v))
        cap = FLAT_GAIN_CAP * abs(gains[stiffest].kp)
        # a region whose valve gain is near zero (the pump-limited plateau) would get a huge gain: cap it
        self.laws = {i: PILaw(type(g)(math.copysign(min(abs(g.kp), cap), g.kp), g.ti), sample_time, lims)
                     for i, g in gains.items()}
        self.history = ModelRateHistory(round(bank.sample_time / sample_time), bank.max_lag + 1)
        self.speed_filter = LowPass(SPEED_FILTER_S, sample_time)
        self.pump_filter = LowPass(PUMP_FILTER_S, sample_time)
        self.feedforward = math.nan
        self.command = math.nan

    @property
    def effective(self) -> float:
        """The valve voltage [V] after the hysteresis inverse."""
        return self.inverse.effective

    def _schedule(self) -> int:
        h = self.history
        x = self.bank.regressor(h.y[:-1], h.u1, h.u2)
        region = self.bank.region(x)
        return region if region in self.laws else self.region

    def _feedforward(self, setpoint, pump, region):
        u, found = self.bank.steady_valve(setpoint, pump)
        if found is None:
            # no well-conditioned region holds the set-point here (out of reach, or on the plateau):
            # the stiffest region's answer, within the limits; the integral does the rest
            lo, hi = self.inverse.effective_limits
            return min(max(self.bank.stiff_valve(setpoint, pump), lo), hi)
        return u

    def reset(self, setpoint, speed, pump, command):
        """Start without a bump in the region of the present operating point."""
        self.adaptive.reset(command, speed, pump)
        self.speed_filter.reset(speed)
        self.pump_filter.reset(pump)
        self.history.fill(speed, command, pump)
        _, region = self.bank.steady_valve(setpoint, pump)
        self.region = region if region in self.laws else self.bank.main_region
        self.feedforward = self._feedforward(setpoint, pump, self.region)
        for law in self.laws.values():
            law.reset_to(command, self.feedforward, setpoint - speed)
        self.command = command

    def _select(self, setpoint, y):
        """The region in charge after this sample's model-rate update."""
        return self._schedule()

    def step(self, setpoint, speed, pump):
        """One 10 ms sample: choose the region, switch laws bumplessly, apply its PI law with the region's feedforward."""
        self.adaptive.observe(speed, pump, setpoint)
        y = self.speed_filter(speed)
        w = self.pump_filter(pump)
        if self.history.add(speed, self.inverse.effective, pump):
            new = self._select(setpoint, y)
            if new != self.region:
                previous = self.laws[self.region].output
                self.region = new
                self.feedforward = self._feedforward(setpoint, w, new)
                if self.bumpless:
                    # the new region's law takes over from the output the old one left (feedforward included)
                    self.laws[new].reset_to(previous, self.feedforward, setpoint - y)
        self.feedforward = self._feedforward(setpoint, w, self.region)
        law = self.laws[self.region]
        e = setpoint - y
        if self.region not in self.bank.feedforward_regions:
            # a flat region (the pump-limited plateau): there the integral may open the valve wide (through
            # the prime mover's droop that still gains a little speed); once the speed asks for the other
            # direction, the valve goes straight back to the stiff region's steady state instead of
            # unwinding that integral at the integral rate
            toward = self.bank.stiff_valve(setpoint, w) - law.output
            if law.gains.kp * e * toward > 0.0 and law.integral * toward < 0.0:
                law.integral = 0.0
        desired = law(e, self.feedforward)
        self.command = self.adaptive(desired)
        return self.command


class MMACController(ScheduledController):
    """Multiple-model adaptive control: the region model with the smallest recent one-step prediction
    error (exponentially weighted over ``window_s``) is in charge; a challenger must beat the
    incumbent by ``switch_ratio`` to take over (no chattering on noise)."""

    name = "mmac"

    def __init__(self, *args, window_s: float = 0.5, switch_ratio: float = 0.7, **kwargs):
        super().__init__(*args, **kwargs)
        self.forget = math.exp(-self.bank.sample_time / window_s)
        self.switch_ratio = switch_ratio
        self.cost = {i: 0.0 for i in self.laws}

    def reset(self, setpoint, speed, pump, command):
        """Start as the scheduled controller and clear the models' recent prediction costs."""
        super().reset(setpoint, speed, pump, command)
        self.cost = {i: 0.0 for i in self.laws}

    def _select(self, setpoint, y):
        h = self.history
        x = self.bank.regressor(h.y[:-1], h.u1, h.u2)
        actual = h.y[-1]
        for i in self.cost:
            e = actual - self.bank.predict(x, i)
            self.cost[i] = self.forget * self.cost[i] + (1.0 - self.forget) * e * e
        best = min(self.cost, key=self.cost.get)
        if best != self.region and self.cost[best] < self.switch_ratio * self.cost[self.region]:
            return best
        return self.region
