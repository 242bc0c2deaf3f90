"""The proportional valve: orifice law, voltage -> spool map and the coil's hysteresis.

docs/plant.md sections 2 and 4. The hysteresis is a *play* (backlash) operator applied to the command
history before integration, a pure function of that history and its initial output (never hidden
state inside an ODE right-hand side, which solvers evaluate at trial points).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from hwpts.errors import ParameterError

MAKEUP_ONSET_PA = 1000.0
"""Suction over which a make-up check valve opens [Pa] (numerical): its flow is K_mu s^2 / (2 w) for a
suction s = -P in [0, w] and K_mu (s - w/2) beyond, none at a positive pressure (:func:`makeup_shape`).
A smooth max over 10 Pa fed an idle chamber from the tank uphill (motor A at 5.5 kPa with the pump
stopped) and, with K_mu = 1e-6, switched over less than the solver's 50 Pa tolerance: a step from
3.0 V / 600 r/min to 2.4 V / 200 r/min took 44,519 steps for 2 s, or failed."""


@numba.njit(cache=True)
def makeup_shape(suction, width):
    """A make-up check valve's opening law: 0 at no suction, ``s^2 / (2 w)`` up to ``w``, then ``s - w/2``
    (continuous with its slope; flow = K_mu * this)."""
    if suction <= 0.0:
        return 0.0
    if suction < width:
        return 0.5 * suction * suction / width
    return suction - 0.5 * width


@numba.njit(cache=True)
def makeup_shape_derivative(suction, width):
    """d makeup_shape / d suction."""
    if suction <= 0.0:
        return 0.0
    if suction < width:
        return suction / width
    return 1.0


@numba.njit(cache=True)
def smooth_max0(x, width):
    """A smooth ``max(x, 0)``: ``0.5 * (x + sqrt(x^2 + width^2))``; exact as ``|x| >> width``."""
    return 0.5 * (x + np.sqrt(x * x + width * width))


@numba.njit(cache=True)
def smooth_max0_derivative(x, width):
    """d smooth_max0 / dx."""
    return 0.5 * (1.0 + x / np.sqrt(x * x + width * width))


@numba.njit(cache=True)
def orifice_shape(pressure_drop, transition_pressure, width):
    """Regularised sqrt of the one-way pressure drop: d / (d^2 + p_cr^2)^(1/4), d = smooth max(dP, 0).

    Equals sqrt(dP) for dP >> p_cr (paper eq. 14), is laminar (linear) near 0, and 0 for dP < 0
    (the check valve), so the Jacobian stays finite.
    """
    d = smooth_max0(pressure_drop, width)
    return d / (d * d + transition_pressure * transition_pressure) ** 0.25


@numba.njit(cache=True)
def orifice_shape_derivative(pressure_drop, transition_pressure, width):
    """d orifice_shape / d pressure_drop."""
    d = smooth_max0(pressure_drop, width)
    s = d * d + transition_pressure * transition_pressure
    return (0.5 * d * d + transition_pressure * transition_pressure) / s**1.25 * smooth_max0_derivative(
        pressure_drop, width
    )


def orifice_flow(area, pressure_drop, parameters):
    """Flow through a valve orifice [m^3/s] (paper eq. 14, regularised, one-way).

    Q = C_D * A * sqrt(2/rho) * dP / (dP^2 + p_cr^2)^(1/4) with dP replaced by a smooth max(dP, 0).
    Works on scalars and arrays.
    """
    area = np.asarray(area, dtype=float)
    dp = np.asarray(pressure_drop, dtype=float)
    coefficient = parameters.discharge_coefficient * math.sqrt(2.0 / parameters.oil_density)
    shape = orifice_shape.py_func(dp, parameters.orifice_transition_pressure, parameters.smoothing_pressure)
    return coefficient * area * shape


def spool_position(effective_voltage, parameters):
    """Spool displacement h [m] from the effective coil command [V] (docs/plant.md section 4).

    h = h_max * clip((v_eff - V_0) / (V_1 - V_0), 0, 1): V_0 = 1.2 V outlet A fully open,
    V_1 = 3.5 V outlet A closed.
    """
    v = np.asarray(effective_voltage, dtype=float)
    span = parameters.valve_voltage_closed - parameters.valve_voltage_open
    return parameters.spool_stroke * np.clip((v - parameters.valve_voltage_open) / span, 0.0, 1.0)


def outlet_areas(spool, parameters):
    """Outlet areas (A_A, A_B) [m^2] for spool position h [m]: complementary and linear in h."""
    frac = np.asarray(spool, dtype=float) / parameters.spool_stroke
    a_a = parameters.max_orifice_area * (1.0 - frac) + parameters.leak_area
    a_b = parameters.max_orifice_area * frac + parameters.leak_area
    return a_a, a_b


@numba.njit(cache=True)
def _play(command, half_width, initial):
    out = np.empty_like(command)
    state = initial
    for k in range(command.shape[0]):
        state = min(max(state, command[k] - half_width), command[k] + half_width)
        out[k] = state
    return out


def play_operator(command, half_width, initial=None):
    """The play (backlash) operator: v_eff[k] = min(max(v_eff[k-1], v[k] - r), v[k] + r).

    Parameters
    ----------
    command : array_like, shape (n,)
        The command history v (e.g. valve voltage [V]).
    half_width : float
        r >= 0; r = 0 gives the identity.
    initial : float, optional
        v_eff[-1], the operator's output before the first sample. Default ``command[0]`` (centred).

    Returns
    -------
    ndarray, shape (n,)
        The effective command; it always stays within +-r of the command.

    Examples
    --------
    >>> play_operator([1.5, 2.0, 2.5, 2.0, 1.5], 0.25).tolist()
    [1.5, 1.75, 2.25, 2.25, 1.75]
    """
    v = np.ascontiguousarray(command, dtype=np.float64).reshape(-1)
    if not (isinstance(half_width, (int, float, np.floating)) and math.isfinite(half_width)) or half_width < 0:
        raise ParameterError(f"half_width must be a finite number >= 0, got {half_width!r}")
    if v.size == 0:
        return v.copy()
    if not np.all(np.isfinite(v)):
        raise ParameterError("command must be finite (no NaN or inf)")
    start = float(v[0]) if initial is None else float(initial)
    if not math.isfinite(start):
        raise ParameterError(f"initial must be finite, got {initial!r}")
    return _play(v, float(half_width), start)
