"""The test bed: the plant as the lab rig records it.

Droop and hysteresis on, sensor noise on the measured speeds (seeded), sampling at a documented
period. It records the way the paper's rig does: the valve command and the *measured* pump speed
are the inputs, the measured motor A speed is the output (paper section V.D).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hwpts.dataset import IODataset
from hwpts.errors import ParameterError
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.profiles import InputProfile
from hwpts.plant.simulate import PlantResponse, simulate_plant

INPUT_NAMES = ("valve_voltage_v", "pump_speed_rpm")
OUTPUT_NAME = "motor_a_speed_rpm"

DEFAULT_SAMPLE_TIME = 0.01
"""Sample period of the test bed's data logger [s] (10 ms; the paper does not state its own)."""

MAX_NOISE_STD_RPM = 1e6  # a thousand times the speeds measured; 1e308 overflowed to inf in the samples
DEFAULT_NOISE_STD_RPM = 2.0
"""Standard deviation of the speed sensors' noise [r/min] (assumed: ~0.1 % of full scale)."""


@dataclass(frozen=True)
class TestBed:
    """The simulated lab rig.

    Attributes
    ----------
    parameters : PlantParameters
        Default: :meth:`PlantParameters.test_bed` (hysteresis r = 0.25 V, droop 3.37).
    sample_time : float
        Logger period [s].
    noise_std_rpm : float
        Gaussian noise on both measured speeds [r/min].
    """

    __test__ = False  # not a pytest test class

    parameters: PlantParameters = field(default_factory=PlantParameters.test_bed)
    sample_time: float = DEFAULT_SAMPLE_TIME
    noise_std_rpm: float = DEFAULT_NOISE_STD_RPM

    def __post_init__(self):
        if not (np.isfinite(self.sample_time) and self.sample_time > 0):
            raise ParameterError(f"sample_time must be a positive number of seconds, got {self.sample_time!r}")
        if not (np.isfinite(self.noise_std_rpm) and 0 <= self.noise_std_rpm <= MAX_NOISE_STD_RPM):
            raise ParameterError(f"noise_std_rpm must be a number from 0 to {MAX_NOISE_STD_RPM:g} r/min, "
                                 f"got {self.noise_std_rpm!r}")

    def run(self, time, valve_voltage, pump_speed_command, seed: int | None = 0, **simulate_options):
        """Simulate and measure: returns (IODataset, PlantResponse).

        The dataset's inputs are ``valve_voltage_v`` (the command) and ``pump_speed_rpm`` (measured,
        after droop, with noise); its output is ``motor_a_speed_rpm`` (measured, with noise). The
        noise-free signals and the states are kept in ``extra``.
        """
        response = simulate_plant(self.parameters, time, valve_voltage, pump_speed_command, **simulate_options)
        return self.measure(response, seed), response

    def record(self, profile: InputProfile, seed: int | None = 0, **simulate_options):
        """Run an :class:`InputProfile` (resampled to this test bed's period if needed)."""
        t = profile.time
        if t.size > 1 and not np.isclose(np.median(np.diff(t)), self.sample_time):
            grid = np.arange(0.0, t[-1] + 0.5 * self.sample_time, self.sample_time)
            idx = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 1)
            return self.run(grid, profile.valve_voltage_v[idx], profile.pump_speed_rpm[idx], seed, **simulate_options)
        return self.run(t, profile.valve_voltage_v, profile.pump_speed_rpm, seed, **simulate_options)

    def measure(self, response: PlantResponse, seed: int | None = 0) -> IODataset:
        """Add the sensors' noise to a simulated response and package it as a dataset."""
        rng = np.random.default_rng(seed)
        n = response.time.size
        noise = self.noise_std_rpm * rng.standard_normal((2, n)) if self.noise_std_rpm > 0 else np.zeros((2, n))
        pump_measured = response.pump_speed_rpm + noise[0]
        motor_measured = response.motor_a_speed_rpm + noise[1]
        extra = {
            "pump_speed_command_rpm": response.pump_speed_command_rpm,
            "pump_speed_true_rpm": response.pump_speed_rpm,
            "motor_a_speed_true_rpm": response.motor_a_speed_rpm,
            "motor_b_speed_rpm": response.motor_b_speed_rpm,
            "pump_pressure_pa": response.pump_pressure_pa,
            "motor_a_pressure_pa": response.motor_a_pressure_pa,
            "motor_b_pressure_pa": response.motor_b_pressure_pa,
            "spool_position_m": response.spool,
            "effective_voltage_v": response.effective_voltage_v,
        }
        return IODataset(
            response.time,
            np.column_stack([response.valve_voltage_v, pump_measured]),
            motor_measured,
            INPUT_NAMES,
            OUTPUT_NAME,
            extra,
        )
