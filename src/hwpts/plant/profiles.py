"""Input profiles: the paper's four validation cases (section V.D, Figs. 8-11) and a rich
identification excitation.

Each profile gives the valve command [V] and the pump (turbine) speed *command* [r/min] on a
uniform time grid [s]. With the test bed's droop on, the measured pump speed falls with load.
The paper does not print its profiles' timings; the values here are our reading of its figures,
each a named, documented choice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hwpts.errors import ParameterError

CASE_NAMES = ("case1", "case2", "case3", "case4")

TRIANGLE_PUMP_COMMAND_RPM = 706.5
"""Pump command of the triangle test: 600 r/min at 1.5 V with the rig's droop (docs/plant.md section 5)."""


@dataclass(frozen=True)
class InputProfile:
    """A named input profile: time [s], valve command [V], pump speed command [r/min]."""

    name: str
    description: str
    time: np.ndarray
    valve_voltage_v: np.ndarray
    pump_speed_rpm: np.ndarray


def _grid(duration, sample_time):
    if not (sample_time > 0 and np.isfinite(sample_time)):
        raise ParameterError(f"sample_time must be a positive number of seconds, got {sample_time!r}")
    return np.arange(int(round(duration / sample_time)) + 1) * sample_time


def case1(sample_time: float = 0.01) -> InputProfile:
    """Case 1 (Fig. 8): constant valve command 2.0 V, pump speed steps 500 -> 800 -> 500 r/min."""
    t = _grid(30.0, sample_time)
    v = np.full_like(t, 2.0)
    w = np.where((t >= 10.0) & (t < 20.0), 800.0, 500.0)
    return InputProfile("case1", "constant valve 2.0 V; pump speed step 500 -> 800 -> 500 r/min", t, v, w)


def case2(sample_time: float = 0.01) -> InputProfile:
    """Case 2 (Fig. 9): valve step from fully open (1.2 V) to fully closed (3.8 V) and back; the
    pump is commanded to a constant 706.5 r/min and droops with the load."""
    t = _grid(30.0, sample_time)
    v = np.where((t >= 10.0) & (t < 20.0), 3.8, 1.2)
    w = np.full_like(t, TRIANGLE_PUMP_COMMAND_RPM)
    return InputProfile("case2", "valve step 1.2 -> 3.8 -> 1.2 V (fully open to fully closed); pump 706.5 r/min command", t, v, w)


def case3(sample_time: float = 0.01) -> InputProfile:
    """Case 3 (Fig. 10): triangle 1.5 -> 3.5 -> 1.5 V over 40 s (after 5 s at rest); the pump
    commanded to 706.5 r/min drops from 600 to ~500 r/min and back with the droop."""
    t = _grid(50.0, sample_time)
    ramp = np.clip((t - 5.0) / 20.0, 0.0, 2.0)
    v = 1.5 + 2.0 * np.where(ramp <= 1.0, ramp, 2.0 - ramp)
    w = np.full_like(t, TRIANGLE_PUMP_COMMAND_RPM)
    return InputProfile("case3", "triangle valve 1.5 -> 3.5 -> 1.5 V; pump 706.5 r/min command", t, v, w)


def case4(sample_time: float = 0.01) -> InputProfile:
    """Case 4 (Fig. 11): sinusoidal valve command 2.4 +- 0.8 V (period 12 s) with pump speed steps
    600 -> 850 -> 400 -> 700 r/min every 15 s, 60 s in all: both inputs strongly varying."""
    t = _grid(60.0, sample_time)
    v = 2.4 + 0.8 * np.sin(2.0 * np.pi * t / 12.0)
    levels = np.array([600.0, 850.0, 400.0, 700.0])
    w = levels[np.minimum((t // 15.0).astype(int), levels.size - 1)]
    return InputProfile("case4", "sinusoidal valve 2.4 +- 0.8 V, 12 s period; pump steps 600/850/400/700 r/min", t, v, w)


CASES = {"case1": case1, "case2": case2, "case3": case3, "case4": case4}


def validation_case(name: str, sample_time: float = 0.01) -> InputProfile:
    """One of the paper's four validation cases by name."""
    try:
        return CASES[name](sample_time)
    except KeyError:
        raise ParameterError(f"unknown case {name!r}; expected one of {list(CASES)}") from None


def identification_excitation(
    duration: float = 600.0,
    sample_time: float = 0.01,
    seed: int = 0,
    voltage_range=(1.2, 3.8),
    pump_range=(200.0, 1000.0),
    hold_range=(0.5, 4.0),
    n_levels: int = 14,
) -> InputProfile:
    """Multi-level random steps of both inputs covering the whole operating range.

    Each input holds a level drawn from ``n_levels`` evenly spaced levels for a random time in
    ``hold_range`` [s]; the two inputs switch independently. Reproducible by ``seed``.
    """
    if duration <= 0:
        raise ParameterError(f"duration must be > 0 s, got {duration!r}")
    rng = np.random.default_rng(seed)
    t = _grid(duration, sample_time)

    def steps(lo, hi):
        levels = np.linspace(lo, hi, n_levels)
        out = np.empty_like(t)
        k = 0
        while k < t.size:
            hold = max(1, int(round(rng.uniform(*hold_range) / sample_time)))
            out[k:k + hold] = rng.choice(levels)
            k += hold
        return out

    v = steps(*voltage_range)
    w = steps(*pump_range)
    return InputProfile(
        "identification",
        f"multi-level random steps: valve {voltage_range[0]}-{voltage_range[1]} V, pump "
        f"{pump_range[0]:g}-{pump_range[1]:g} r/min, holds {hold_range[0]}-{hold_range[1]} s, seed {seed}",
        t, v, w,
    )
