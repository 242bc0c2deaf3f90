"""Steady states F(x, h, w_p) = 0 of the HWPTS, vectorised over many operating points.

The static equations have a monotone structure that makes them solvable exactly and without
initial guesses: for a given pump pressure P_p each motor branch has one shaft speed balancing its
flow (the orifice flow falls and the motor's demand rises with speed), and the pump-line balance
falls monotonically in P_p. So each point is a bracketed 1-D solve on P_p around bracketed 1-D
solves of the two branches, each a Newton iteration with analytic derivatives (the outer one through
the branches' implicit dependence on P_p) that falls back to bisection whenever a step would leave
the bracket, so it always converges. Newton on the full 5-state system cycles across
the check-valve kink near the fracture line; this cannot. Compiled with numba; the points are independent,
so a sweep is a map over chunks of points (docs/plant.md section 7).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numba
import numpy as np

from hwpts.errors import ParameterError, SimulationError
from hwpts.plant.dynamics import N_STATES, pump_speed_actual, pump_speed_slope
from hwpts.plant.parameters import PARAMETER_INDEX as _I
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.valve import (
    MAKEUP_ONSET_PA,
    makeup_shape,
    makeup_shape_derivative,
    orifice_shape,
    orifice_shape_derivative,
    play_operator,
    smooth_max0,
    smooth_max0_derivative,
    spool_position,
)
from hwpts.units import RAD_S_PER_RPM, RPM_PER_RAD_S

BRANCHES = ("none", "up", "down")

# parameter positions in PlantParameters.as_array() (compile-time constants for numba)
_AUX_OPENING_PRESSURE = _I["aux_opening_pressure"]
_COULOMB_SPEED_WIDTH = _I["coulomb_speed_width"]
_DISCHARGE_COEFFICIENT = _I["discharge_coefficient"]
_LEAK_AREA = _I["leak_area"]
_MAKEUP_GAIN = _I["makeup_gain"]
_MAX_ORIFICE_AREA = _I["max_orifice_area"]
_MOTOR_A_DAMPING = _I["motor_a_damping"]
_MOTOR_A_DISPLACEMENT = _I["motor_a_displacement"]
_MOTOR_A_LEAKAGE = _I["motor_a_leakage"]
_MOTOR_A_LOAD_TORQUE = _I["motor_a_load_torque"]
_MOTOR_B_DAMPING = _I["motor_b_damping"]
_MOTOR_B_DISPLACEMENT = _I["motor_b_displacement"]
_MOTOR_B_LEAKAGE = _I["motor_b_leakage"]
_MOTOR_B_LOAD_TORQUE = _I["motor_b_load_torque"]
_OIL_DENSITY = _I["oil_density"]
_ORIFICE_TRANSITION_PRESSURE = _I["orifice_transition_pressure"]
_PUMP_DISPLACEMENT = _I["pump_displacement"]
_PUMP_LEAKAGE = _I["pump_leakage"]
_RELIEF_GAIN = _I["relief_gain"]
_RELIEF_PRESSURE = _I["relief_pressure"]
_SMOOTHING_PRESSURE = _I["smoothing_pressure"]
_SPOOL_STROKE = _I["spool_stroke"]
_GENERATOR_SLIP_GAIN = _I["generator_slip_gain"]
_GENERATOR_SYNCHRONOUS_SPEED = _I["generator_synchronous_speed"]

_FLOW_SCALE = 1e-4  # m^3/s, typical flow: the reported residual is divided by it


@numba.njit(cache=True)
def _branch(w, pp, area, opening, dm, cs, damping, torque, ws, c, pcr, eps, kmu, out, slip=0.0, w_sync=0.0):
    """Flow balance g of one motor branch at shaft speed w and supply pressure pp (g falls with w).

    ``slip``, ``w_sync``: the optional generator's slip torque slip * (w - w_sync) (0: none).
    Writes (g, dg/dw, dg/dpp, dQ/dpp at fixed w, dQ/dw) into out; returns the orifice flow Q.
    """
    th = math.tanh(w / ws)
    pm = (damping * w + torque * th + slip * (w - w_sync)) / dm
    dpm = (damping + torque / ws * (1.0 - th * th) + slip) / dm
    dp = pp - pm - opening
    q = c * area * orifice_shape(dp, pcr, eps)
    dq = c * area * orifice_shape_derivative(dp, pcr, eps)
    mu = kmu * makeup_shape(-pm, MAKEUP_ONSET_PA)
    dmu = kmu * makeup_shape_derivative(-pm, MAKEUP_ONSET_PA)
    out[0] = q + mu - dm * w - cs * pm
    out[1] = -dq * dpm - dmu * dpm - dm - cs * dpm
    out[2] = dq
    out[3] = dq
    out[4] = -dq * dpm
    return q


@numba.njit(cache=True)
def _rtsafe_step(x, f, df, lo, hi, dx, dx_old):
    """One step of rtsafe (Numerical Recipes) for a decreasing f bracketed by [lo, hi].

    Narrows the bracket with the sign of f, then takes the Newton step, or bisects when Newton
    leaves the bracket or does not halve the previous step. Returns (x, dx, dx_old, lo, hi).
    """
    if f > 0.0:
        lo = x
    else:
        hi = x
    newton = x - f / df if df < 0.0 else lo - 1.0
    if not (lo < newton < hi) or abs(2.0 * f) > abs(dx_old * df):
        dx_old = dx
        dx = 0.5 * (hi - lo)
        return lo + dx, dx, dx_old, lo, hi
    return newton, newton - x, dx, lo, hi


@numba.njit(cache=True)
def _branch_speed(pp, area, opening, dm, cs, damping, torque, ws, c, pcr, eps, kmu, out, guess, slip=0.0, w_sync=0.0):
    """The unique shaft speed balancing a motor branch: safeguarded Newton on a bracket.

    ``guess`` (e.g. the solution at a nearby pressure) starts the iteration when inside the
    bracket. On return out holds the branch's derivatives at the solution (see :func:`_branch`).
    """
    lo = -1.0
    hi = max(pp, 1.0) * dm / damping + 10.0
    _branch(lo, pp, area, opening, dm, cs, damping, torque, ws, c, pcr, eps, kmu, out, slip, w_sync)
    if out[0] <= 0.0:
        return lo
    w = guess if lo < guess < hi else min(max(pp - opening, 0.0) * dm * dm / (damping * dm + 1e-3), 0.5 * hi)
    dx_old = hi - lo
    dx = dx_old
    for _ in range(200):
        _branch(w, pp, area, opening, dm, cs, damping, torque, ws, c, pcr, eps, kmu, out, slip, w_sync)
        w, dx, dx_old, lo, hi = _rtsafe_step(w, out[0], out[1], lo, hi, dx, dx_old)
        if abs(dx) <= 1e-12 * (1.0 + abs(w)):
            break
    _branch(w, pp, area, opening, dm, cs, damping, torque, ws, c, pcr, eps, kmu, out, slip, w_sync)
    return w


@numba.njit(cache=True)
def _pump_balance(pp, h, wp_cmd, p, speeds, work):
    """Pump-line flow balance G at pump pressure pp (G falls with pp); writes the shaft speeds.

    Returns G; work[0] receives dG/dpp, through each branch's implicit dependence w(pp).
    """
    c = p[_DISCHARGE_COEFFICIENT] * math.sqrt(2.0 / p[_OIL_DENSITY])
    frac = h / p[_SPOOL_STROKE]
    area_a = p[_MAX_ORIFICE_AREA] * (1.0 - frac) + p[_LEAK_AREA]
    area_b = p[_MAX_ORIFICE_AREA] * frac + p[_LEAK_AREA]
    eps = p[_SMOOTHING_PRESSURE]
    pcr = p[_ORIFICE_TRANSITION_PRESSURE]
    kmu = p[_MAKEUP_GAIN]
    ws = p[_COULOMB_SPEED_WIDTH]
    out = work[1:]
    wa = _branch_speed(pp, area_a, 0.0, p[_MOTOR_A_DISPLACEMENT], p[_MOTOR_A_LEAKAGE], p[_MOTOR_A_DAMPING],
                       p[_MOTOR_A_LOAD_TORQUE], ws, c, pcr, eps, kmu, out, speeds[0],
                       p[_GENERATOR_SLIP_GAIN], p[_GENERATOR_SYNCHRONOUS_SPEED])
    qa = c * area_a * orifice_shape(pp - (p[_MOTOR_A_DAMPING] * wa + p[_MOTOR_A_LOAD_TORQUE] * math.tanh(wa / ws)
                                          + p[_GENERATOR_SLIP_GAIN] * (wa - p[_GENERATOR_SYNCHRONOUS_SPEED]))
                                    / p[_MOTOR_A_DISPLACEMENT], pcr, eps)
    dqa = out[3] + out[4] * (-out[2] / out[1])
    wb = _branch_speed(pp, area_b, p[_AUX_OPENING_PRESSURE], p[_MOTOR_B_DISPLACEMENT], p[_MOTOR_B_LEAKAGE],
                       p[_MOTOR_B_DAMPING], p[_MOTOR_B_LOAD_TORQUE], ws, c, pcr, eps, kmu, out, speeds[1])
    qb = c * area_b * orifice_shape(pp - (p[_MOTOR_B_DAMPING] * wb + p[_MOTOR_B_LOAD_TORQUE] * math.tanh(wb / ws))
                                    / p[_MOTOR_B_DISPLACEMENT] - p[_AUX_OPENING_PRESSURE], pcr, eps)
    dqb = out[3] + out[4] * (-out[2] / out[1])
    speeds[0] = wa
    speeds[1] = wb
    qp = p[_PUMP_DISPLACEMENT] * pump_speed_actual(pp, wp_cmd, p) - p[_PUMP_LEAKAGE] * pp
    qrv = p[_RELIEF_GAIN] * smooth_max0(pp - p[_RELIEF_PRESSURE], eps)
    work[0] = (p[_PUMP_DISPLACEMENT] * pump_speed_slope(pp, wp_cmd, p) - p[_PUMP_LEAKAGE]
               - kmu * makeup_shape_derivative(-pp, MAKEUP_ONSET_PA) - dqa - dqb
               - p[_RELIEF_GAIN] * smooth_max0_derivative(pp - p[_RELIEF_PRESSURE], eps))
    return qp + kmu * makeup_shape(-pp, MAKEUP_ONSET_PA) - qa - qb - qrv


@numba.njit(cache=True)
def _solve_points(spool, wp_cmd, p, out, iterations, residual, tol, max_iter):
    """Steady state of each point: safeguarded Newton on P_p around the branches' own solves."""
    n = spool.shape[0]
    speeds = np.empty(2)
    work = np.empty(6)
    for k in range(n):
        h = spool[k]
        w = wp_cmd[k]
        speeds[0] = -10.0  # no warm start for the first branch solves of a point
        speeds[1] = -10.0
        lo = 0.0
        hi = p[_RELIEF_PRESSURE]
        f_hi = _pump_balance(hi, h, w, p, speeds, work)
        grow = 0
        while f_hi > 0.0 and grow < 60:
            lo = hi
            hi *= 2.0
            f_hi = _pump_balance(hi, h, w, p, speeds, work)
            grow += 1
        pp = lo if grow else 0.5 * hi
        dx_old = hi - lo
        dx = dx_old
        it = 0
        converged = False
        while it < max_iter:
            it += 1
            f = _pump_balance(pp, h, w, p, speeds, work)
            pp, dx, dx_old, lo, hi = _rtsafe_step(pp, f, work[0], lo, hi, dx, dx_old)
            if abs(dx) <= tol * (1.0 + pp):
                converged = True
                break
        f = _pump_balance(pp, h, w, p, speeds, work)
        wa = speeds[0]
        wb = speeds[1]
        ws = p[_COULOMB_SPEED_WIDTH]
        out[k, 0] = pp
        out[k, 1] = (p[_MOTOR_A_DAMPING] * wa + p[_MOTOR_A_LOAD_TORQUE] * math.tanh(wa / ws)
                     + p[_GENERATOR_SLIP_GAIN] * (wa - p[_GENERATOR_SYNCHRONOUS_SPEED])) / p[_MOTOR_A_DISPLACEMENT]
        out[k, 2] = (p[_MOTOR_B_DAMPING] * wb + p[_MOTOR_B_LOAD_TORQUE] * math.tanh(wb / ws)) / p[_MOTOR_B_DISPLACEMENT]
        out[k, 3] = wa
        out[k, 4] = wb
        iterations[k] = it
        residual[k] = 0.0 if converged else abs(f) / _FLOW_SCALE


@dataclass(frozen=True)
class SteadyState:
    """Steady operating points (arrays of one shape, the broadcast shape of the inputs).

    ``state`` has that shape + (5,), in SI units. Speeds are also given in r/min.
    """

    valve_voltage_v: np.ndarray
    effective_voltage_v: np.ndarray
    pump_speed_command_rpm: np.ndarray
    state: np.ndarray
    pump_speed_rpm: np.ndarray
    iterations: np.ndarray

    @property
    def pump_pressure_pa(self):
        """Pump pressure P_p [Pa] at each operating point."""
        return self.state[..., 0]

    @property
    def motor_a_pressure_pa(self):
        """Motor A inlet pressure P_A [Pa] at each operating point."""
        return self.state[..., 1]

    @property
    def motor_b_pressure_pa(self):
        """Motor B inlet pressure P_B [Pa] at each operating point."""
        return self.state[..., 2]

    @property
    def motor_a_speed_rpm(self):
        """Motor A (generator) speed [r/min] at each operating point."""
        return self.state[..., 3] * RPM_PER_RAD_S

    @property
    def motor_b_speed_rpm(self):
        """Motor B speed [r/min] at each operating point."""
        return self.state[..., 4] * RPM_PER_RAD_S


def _check_operating_points(valve_voltage, pump_speed_rpm):
    from hwpts.plant.parameters import check_input_ranges

    v = np.asarray(valve_voltage, dtype=float)
    w = np.asarray(pump_speed_rpm, dtype=float)
    check_input_ranges(v, w)
    return np.broadcast_arrays(v, w)


def solve_steady_state(parameters: PlantParameters, spool, pump_speed_command, tol=1e-12, max_iter=200):
    """Raw solver: steady states for arrays of spool positions [m] and pump speed commands [rad/s].

    Returns (state (n, 5), iterations (n,)). Raises SimulationError naming the points that did not
    converge.
    """
    h = np.ascontiguousarray(spool, dtype=np.float64).reshape(-1)
    w = np.ascontiguousarray(pump_speed_command, dtype=np.float64).reshape(-1)
    n = h.shape[0]
    out = np.empty((n, N_STATES))
    its = np.zeros(n, dtype=np.int64)
    res = np.zeros(n)
    _solve_points(h, w, parameters.as_array(), out, its, res, tol, max_iter)
    bad = ~(res == 0.0)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise SimulationError(
            f"steady state did not converge at {int(bad.sum())} of {n} operating points; first: spool "
            f"{h[k]:.4g} m, pump {w[k] * RPM_PER_RAD_S:.1f} r/min (scaled residual {res[k]:.3g} after {its[k]} iterations)"
        )
    return out, its


def steady_state(
    parameters: PlantParameters,
    valve_voltage,
    pump_speed_rpm,
    branch: str = "none",
) -> SteadyState:
    """Steady state at valve command(s) [V] and pump speed command(s) [r/min] (arrays broadcast).

    branch: ``"none"`` - the averaged valve (no hysteresis, v_eff = v); ``"up"`` - reached by
    increasing voltage (v_eff = v - r); ``"down"`` - reached by decreasing voltage (v_eff = v + r).
    """
    if branch not in BRANCHES:
        raise ParameterError(f"branch must be one of {list(BRANCHES)}, got {branch!r}")
    v, w = _check_operating_points(valve_voltage, pump_speed_rpm)
    r = parameters.hysteresis_half_width
    offset = {"none": 0.0, "up": -r, "down": r}[branch]
    v_eff = v + offset
    state, its = solve_steady_state(parameters, spool_position(v_eff, parameters), w * RAD_S_PER_RPM)
    state = state.reshape(v.shape + (N_STATES,))
    wp = pump_speed_actual.py_func(state[..., 0], w * RAD_S_PER_RPM, parameters.as_array())
    return SteadyState(v, v_eff, w, state, wp * RPM_PER_RAD_S, its.reshape(v.shape))


@dataclass(frozen=True)
class SweepResult:
    """Up and down steady-state sweeps on a grid (paper section V.A, Figs. 3-5).

    Surfaces are motor A speed [r/min] with shape (n_voltages, n_pump_speeds).
    """

    voltages_v: np.ndarray
    pump_speeds_rpm: np.ndarray
    up_rpm: np.ndarray
    down_rpm: np.ndarray

    @property
    def average_rpm(self) -> np.ndarray:
        """The averaged surface (Fig. 5): the mean of the up and down sweeps, cancelling hysteresis."""
        return 0.5 * (self.up_rpm + self.down_rpm)

    @property
    def gap_percent(self) -> np.ndarray:
        """Normalised hysteresis gap (Fig. 4): (up - down) in % of the full scale of the response."""
        full_scale = max(np.max(self.up_rpm), np.max(self.down_rpm)) - min(np.min(self.up_rpm), np.min(self.down_rpm))
        return 100.0 * (self.up_rpm - self.down_rpm) / full_scale if full_scale > 0 else np.zeros_like(self.up_rpm)

    @property
    def points_per_sweep(self) -> int:
        """Operating points in one sweep (voltages x pump speeds)."""
        return int(self.up_rpm.size)


def sweep_effective_voltages(voltages, half_width):
    """Effective coil commands along an up sweep and a down sweep of ``voltages`` (play operator).

    The up sweep starts from below (the play engaged, v_eff = v_0 - r); the down sweep from above.
    """
    v = np.asarray(voltages, dtype=float)
    up = play_operator(v, half_width, initial=v[0] - half_width)
    down = play_operator(v[::-1], half_width, initial=v[-1] + half_width)[::-1]
    return up, down


def sweep(
    parameters: PlantParameters,
    voltages,
    pump_speeds_rpm,
    progress: bool | None = None,
    chunk_size: int = 256,
) -> SweepResult:
    """Up and down steady-state sweeps of the valve command at every pump speed of the grid.

    A sweep with hysteresis is a sequence of steady states of v_eff along the sweep direction
    (docs/plant.md section 7). ``progress=None`` shows a progress bar only on a terminal.
    """
    v = np.asarray(voltages, dtype=float).reshape(-1)
    w = np.asarray(pump_speeds_rpm, dtype=float).reshape(-1)
    if v.size == 0 or w.size == 0:
        raise ParameterError("the sweep grid is empty: give at least one voltage and one pump speed")
    _check_operating_points(v[:, None], w[None, :])
    up_eff, down_eff = sweep_effective_voltages(v, parameters.hysteresis_half_width)
    v_eff = np.concatenate([up_eff, down_eff])
    vv, ww = np.meshgrid(v_eff, w, indexing="ij")
    spool = spool_position(vv, parameters).ravel()
    wp = (ww * RAD_S_PER_RPM).ravel()
    speeds = np.empty(spool.size)
    if progress is None:
        progress = sys.stderr.isatty()
    from tqdm import tqdm

    with tqdm(total=spool.size, desc="steady-state sweep", unit="pt", disable=not progress, leave=False) as bar:
        for start in range(0, spool.size, chunk_size):
            stop = min(start + chunk_size, spool.size)
            state, _ = solve_steady_state(parameters, spool[start:stop], wp[start:stop])
            speeds[start:stop] = state[:, 3] * RPM_PER_RAD_S
            bar.update(stop - start)
    speeds = speeds.reshape(2 * v.size, w.size)
    return SweepResult(v, w, speeds[: v.size], speeds[v.size:])
