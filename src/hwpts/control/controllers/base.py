"""Building blocks shared by the controllers: the hysteresis inverse, a PI law with anti-windup,
the model-rate history, and the controller interface the closed loop calls.

Every controller acts on the *effective* valve voltage (the output of the valve's play, the input
``valve_voltage_play_v`` the model bank was identified with) and turns it into a coil command
through :class:`HysteresisInverse`; the ``-no-inverse`` variants command the effective voltage
they want directly, as a controller unaware of the play would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

VALVE_LIMITS_V = (1.2, 3.8)
"""The coil command's range [V] (the paper's 1.2-3.8 V)."""


@dataclass(frozen=True)
class PIGains:
    """PI gains on the effective valve voltage: kp [V per r/min], ti [s] (integral time)."""

    kp: float
    ti: float

    @classmethod
    def simc(cls, gain: float, time_constant: float, dead_time: float, closed_loop_time: float) -> PIGains:
        """Skogestad's SIMC rule for K e^(-theta s) / (tau s + 1): kp = tau / (K (tau_c + theta)),
        ti = min(tau, 4 (tau_c + theta)) (Skogestad, J. Process Control 13, 2003, eq. 22-23)."""
        kp = time_constant / (gain * (closed_loop_time + dead_time))
        ti = min(time_constant, 4.0 * (closed_loop_time + dead_time))
        return cls(float(kp), float(ti))


class HysteresisInverse:
    """Inverse of the valve's play operator of half-width r (docs/plant.md section 4).

    To move the play's output to v, the command must be v + r going up and v - r going down; a
    desired change smaller than ``deadband`` holds the command (no reversal on noise). The
    estimate of the play's output is updated with the command actually sent (after clipping).
    With ``enabled=False`` the desired effective voltage is commanded as it is.
    """

    def __init__(self, half_width: float, enabled: bool = True, deadband: float = 0.003,
                 limits=VALVE_LIMITS_V):
        self.r = float(half_width)
        self.enabled = bool(enabled)
        self.deadband = float(deadband)
        self.limits = (float(limits[0]), float(limits[1]))
        self.effective = 0.5 * (limits[0] + limits[1])
        self.command = self.effective

    @property
    def effective_limits(self) -> tuple[float, float]:
        """The effective voltages the controller may ask for."""
        if self.enabled:
            return self.limits[0] + self.r, self.limits[1] - self.r
        return self.limits

    def reset(self, command: float) -> None:
        """The valve rests at ``command`` with its play centred on it."""
        self.command = float(command)
        self.effective = float(command)

    def set_width(self, half_width: float, effective: float) -> None:
        """A new estimate of the play's half-width [V] and of its present output [V] (online estimation)."""
        self.r = float(half_width)
        lo, hi = self.command - self.r, self.command + self.r
        self.effective = min(max(float(effective), lo), hi)

    def __call__(self, desired: float) -> float:
        lo, hi = self.limits
        if self.enabled:
            if desired > self.effective + self.deadband:
                cmd = desired + self.r
            elif desired < self.effective - self.deadband:
                cmd = desired - self.r
            else:
                cmd = self.command
        else:
            cmd = desired
        cmd = min(max(cmd, lo), hi)
        self.command = cmd
        self.effective = min(max(self.effective, cmd - self.r), cmd + self.r)
        return cmd


class PILaw:
    """u = u_ff + kp e + I, the integrator clamped so that u stays within the limits (anti-windup by
    conditional integration: the integral never grows past what the actuator can deliver)."""

    def __init__(self, gains: PIGains, sample_time: float, limits):
        self.gains = gains
        self.dt = float(sample_time)
        self.limits = limits
        self.integral = 0.0
        self.output = 0.5 * (limits[0] + limits[1])

    def reset_to(self, output: float, feedforward: float, error: float) -> None:
        """Bumpless (re)start: set the integral so that the law now outputs ``output``."""
        self.integral = output - feedforward - self.gains.kp * error
        self.output = output

    def __call__(self, error: float, feedforward: float, hold: bool = False) -> float:
        """One sample; ``hold`` keeps the integral as it is (conditional integration)."""
        g = self.gains
        p = feedforward + g.kp * error
        integral = self.integral if hold else self.integral + g.kp * self.dt / g.ti * error
        lo, hi = self.limits
        integral = min(max(integral, lo - p), hi - p)
        self.integral = integral
        self.output = p + integral
        return self.output


class ModelRateHistory:
    """Block means of the loop's signals at the model's sample period (as the identification data
    were decimated), newest last, long enough for the model's regressor."""

    def __init__(self, ratio: int, length: int):
        self.ratio = max(1, int(ratio))
        self.length = int(length) + 2
        self.y: list[float] = []
        self.u1: list[float] = []
        self.u2: list[float] = []
        self._acc = np.zeros(3)
        self._count = 0

    def fill(self, y: float, u1: float, u2: float) -> None:
        """Fill the whole history with one operating point (speed [r/min], valve [V], pump [r/min]): a start in steady state."""
        self.y = [y] * self.length
        self.u1 = [u1] * self.length
        self.u2 = [u2] * self.length
        self._acc[:] = 0.0
        self._count = 0

    def add(self, y: float, u1: float, u2: float) -> bool:
        """Add one loop sample; True when a model-rate sample was completed."""
        self._acc += (y, u1, u2)
        self._count += 1
        if self._count < self.ratio:
            return False
        m = self._acc / self._count
        for seq, v in ((self.y, m[0]), (self.u1, m[1]), (self.u2, m[2])):
            seq.append(float(v))
            del seq[0]
        self._acc[:] = 0.0
        self._count = 0
        return True


class LowPass:
    """First-order filter y += a (x - y), a = dt / (tau + dt)."""

    def __init__(self, time_constant: float, sample_time: float):
        self.a = 1.0 if time_constant <= 0 else sample_time / (time_constant + sample_time)
        self.value = math.nan

    def reset(self, value: float) -> None:
        """Set the filter's state to ``value`` (no transient from zero)."""
        self.value = float(value)

    def __call__(self, x: float) -> float:
        self.value += self.a * (x - self.value)
        return self.value


class Controller:
    """Interface of a speed controller in the loop (one call per 10 ms sample).

    ``reset(setpoint, speed, pump, command)`` starts it bumplessly in the steady state the loop
    starts in; ``step(setpoint, speed, pump)`` returns the coil command [V] from the measured
    motor A speed and pump speed [r/min]. ``region`` is the active mode (-1: none) and
    ``effective`` the controller's estimate of the compensated (play-output) valve voltage.
    """

    name = "controller"
    has_modes = False

    def __init__(self, sample_time: float = 0.01):
        self.sample_time = float(sample_time)
        self.region = -1

    @property
    def effective(self) -> float:  # pragma: no cover - overridden
        """The valve voltage [V] the model sees: the command after the hysteresis inverse (or the command itself)."""
        return math.nan

    def reset(self, setpoint: float, speed: float, pump: float, command: float) -> None:  # pragma: no cover
        """Start in steady state at ``speed`` [r/min] and ``pump`` [r/min] with the valve at ``command`` [V] (bumpless start)."""
        raise NotImplementedError

    def step(self, setpoint: float, speed: float, pump: float) -> float:  # pragma: no cover
        """One 10 ms sample: the valve command [V] for the measured ``speed`` and ``pump`` [r/min] and the ``setpoint`` [r/min]."""
        raise NotImplementedError
