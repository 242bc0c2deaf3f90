"""Dynamic simulation of the HWPTS on a sample grid with zero-order-hold inputs.

The integrator is the L-stable two-stage Rosenbrock method ROS2 (Verwer, Spee, Blom & Hundsdorfer,
SIAM J. Sci. Comput. 20(4), 1999) with the analytic Jacobian and adaptive steps, compiled with
numba. It is restarted at every sample instant, where the held inputs jump. The model is
moderately stiff (eigenvalues from about -7 to -4e4 1/s, docs/plant.md section 7): an explicit method
needs ~100k steps for 10 s; this one needs a few per sample.

The valve hysteresis (play operator) is applied to the command history *before* integration;
an optional spool lag tau_v adds a sixth state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from hwpts._linalg import lu_factor as _lu_factor
from hwpts._linalg import lu_solve as _lu_solve
from hwpts.errors import DataError, SimulationError
from hwpts.plant.dynamics import N_STATES, jacobian_into, pump_speed_actual, rhs_into
from hwpts.plant.parameters import PARAMETER_INDEX as _I
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.steady_state import solve_steady_state
from hwpts.plant.valve import play_operator, spool_position
from hwpts.units import RAD_S_PER_RPM, RPM_PER_RAD_S

_TAU = _I["spool_time_constant"]
_GAMMA = 1.0 + 1.0 / math.sqrt(2.0)
_NZ = N_STATES + 1  # the 5 states + the spool position

# the grid is integrated in chunks of CHUNK intervals, a hold longer than LONG_HOLD seconds cut
# into pieces of at most that length: between two calls of the compiled loop Python runs its
# signal handlers (a profile of 10^6 s in one call ignored Ctrl-C and SIGTERM until it ended)
CHUNK = 2000
LONG_HOLD = 10.0
MAX_DURATION_S = 1e6  # longest run simulated [s] (11.6 days of the test bed; held inputs: some 17 s here)
PROGRESS_AFTER = 600.0  # simulated seconds beyond which ``progress=True`` shows a bar (10 min of the rig: ~10 s here)

DEFAULT_RTOL = 1e-5
DEFAULT_ATOL = (50.0, 50.0, 50.0, 1e-3, 1e-3, 1e-9)
"""Absolute tolerances: pressures [Pa], speeds [rad/s], spool [m]."""


@numba.njit(cache=True)
def _f(z, h_cmd, wp_cmd, p, out):
    rhs_into(z, z[N_STATES], wp_cmd, p, out)
    tau = p[_TAU]
    out[N_STATES] = (h_cmd - z[N_STATES]) / tau if tau > 0.0 else 0.0


@numba.njit(cache=True)
def _integrate(t, h_cmd, wp_cmd, p, z0, rtol, atol, max_step, out, stats, hstate):
    """ROS2 with step control over the sample grid t; out[k] = z(t[k]). Returns -1 or a failed index.
    ``hstate[0]``: the step size to start with, and on return the one to go on with (a grid
    integrated in chunks steps as in one piece)."""
    n = t.shape[0]
    z = z0.copy()
    for i in range(_NZ):
        out[0, i] = z[i]
    jac5 = np.empty((N_STATES, N_STATES))
    dfdh = np.empty(N_STATES)
    w = np.empty((_NZ, _NZ))
    piv = np.empty(_NZ, dtype=np.int64)
    k1 = np.empty(_NZ)
    k2 = np.empty(_NZ)
    zt = np.empty(_NZ)
    zn = np.empty(_NZ)
    ft = np.empty(_NZ)
    tau = p[_TAU]
    hstep = hstate[0]
    for k in range(n - 1):
        if tau <= 0.0:
            z[N_STATES] = h_cmd[k]
        t0 = t[k]
        t1 = t[k + 1]
        tc = t0
        guard = 0
        # steps allowed in this interval: a long one (6000 s of constant inputs between two rows)
        # needs (t1 - t0) / max_step of them, and ran out at 100,000 (steps below 1 ms earn none:
        # the guard still stops a step size that collapses)
        limit = 100000 + int(4.0 * (t1 - t0) / max(max_step, 1e-3))
        while tc < t1 - 1e-12 * (1.0 + abs(t1)):
            guard += 1
            if guard > limit:
                return k
            hh = min(hstep, t1 - tc, max_step)
            # W = I - gamma h J (augmented 6 x 6 Jacobian)
            jacobian_into(z, z[N_STATES], wp_cmd[k], p, jac5, dfdh)
            stats[1] += 1
            for i in range(_NZ):
                for j in range(_NZ):
                    w[i, j] = 0.0
            for i in range(N_STATES):
                for j in range(N_STATES):
                    w[i, j] = -_GAMMA * hh * jac5[i, j]
                w[i, N_STATES] = -_GAMMA * hh * dfdh[i]
            if tau > 0.0:
                w[N_STATES, N_STATES] = _GAMMA * hh / tau
            for i in range(_NZ):
                w[i, i] += 1.0
            if not _lu_factor(w, piv):
                hstep = hh * 0.25
                if hstep < 1e-12:
                    return k
                continue
            _f(z, h_cmd[k], wp_cmd[k], p, k1)
            _lu_solve(w, piv, k1)
            for i in range(_NZ):
                zt[i] = z[i] + hh * k1[i]
            _f(zt, h_cmd[k], wp_cmd[k], p, ft)
            stats[2] += 2
            for i in range(_NZ):
                k2[i] = ft[i] - 2.0 * k1[i]
            _lu_solve(w, piv, k2)
            err = 0.0
            ok = True
            for i in range(_NZ):
                zn[i] = z[i] + hh * (1.5 * k1[i] + 0.5 * k2[i])
                if not math.isfinite(zn[i]):
                    ok = False
                sc = atol[i] + rtol * max(abs(z[i]), abs(zn[i]))
                e = 0.5 * hh * (k1[i] + k2[i]) / sc
                err += e * e
            err = math.sqrt(err / _NZ)
            if ok and err <= 1.0:
                for i in range(_NZ):
                    z[i] = zn[i]
                tc += hh
                stats[0] += 1
                fac = 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 / math.sqrt(err)))
                if hh < hstep and tc >= t1 - 1e-12 * (1.0 + abs(t1)):
                    pass  # a step shortened to hit the sample instant: keep the step size
                else:
                    hstep = hh * fac
            else:
                stats[3] += 1
                hstep = hh * (0.25 if not ok else max(0.2, 0.9 / math.sqrt(err)))
                if hstep < 1e-12:
                    return k
        for i in range(_NZ):
            out[k + 1, i] = z[i]
    hstate[0] = hstep
    return -1


def _held_grid(t: np.ndarray, long_hold: float):
    """``(grid, source, rows)``: the instants ``t`` with every hold longer than ``long_hold`` cut
    into equal pieces of at most that length, for each grid instant the sample whose inputs hold
    there, and the grid index of each instant of ``t``."""
    steps = np.diff(t)
    pieces = np.maximum(1, np.ceil(steps / long_hold).astype(np.int64)) if t.size > 1 else np.zeros(0, np.int64)
    rows = np.concatenate([[0], np.cumsum(pieces)])
    if not np.any(pieces > 1):
        return t, np.arange(t.size), rows
    source = np.repeat(np.arange(t.size - 1), pieces)
    within = np.arange(source.size) - np.repeat(rows[:-1], pieces)
    grid = np.concatenate([t[source] + steps[source] * within / pieces[source], t[-1:]])
    return grid, np.concatenate([source, [t.size - 1]]), rows


@dataclass(frozen=True)
class SolverStats:
    """Work done by the integrator (for stiffness budgets)."""

    steps: int
    jacobian_evaluations: int
    rhs_evaluations: int
    rejected_steps: int


@dataclass(frozen=True)
class PlantResponse:
    """Result of :func:`simulate_plant` on the sample grid ``time`` (SI states, speeds also in r/min).

    ``state[k]`` is x(t_k); the inputs ``valve_voltage_v[k]`` and ``pump_speed_command_rpm[k]`` are
    held over [t_k, t_{k+1}).
    """

    time: np.ndarray
    state: np.ndarray
    spool: np.ndarray
    valve_voltage_v: np.ndarray
    effective_voltage_v: np.ndarray
    pump_speed_command_rpm: np.ndarray
    pump_speed_rpm: np.ndarray
    stats: SolverStats = field(compare=False)

    @property
    def pump_pressure_pa(self):
        """Pump pressure P_p [Pa] per sample."""
        return self.state[:, 0]

    @property
    def motor_a_pressure_pa(self):
        """Motor A inlet pressure P_A [Pa] per sample."""
        return self.state[:, 1]

    @property
    def motor_b_pressure_pa(self):
        """Motor B inlet pressure P_B [Pa] per sample."""
        return self.state[:, 2]

    @property
    def motor_a_speed_rpm(self):
        """Motor A (generator) speed [r/min] per sample."""
        return self.state[:, 3] * RPM_PER_RAD_S

    @property
    def motor_b_speed_rpm(self):
        """Motor B speed [r/min] per sample."""
        return self.state[:, 4] * RPM_PER_RAD_S


def _as_signal(name, values, n):
    a = np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=float), (n,)), dtype=np.float64)
    if not np.all(np.isfinite(a)):
        raise DataError(f"{name} has a non-finite value (NaN or inf) at row {int(np.argmax(~np.isfinite(a)))}")
    return a


def simulate_plant(
    parameters: PlantParameters,
    time,
    valve_voltage,
    pump_speed,
    initial_state=None,
    valve_initial=None,
    rtol: float = DEFAULT_RTOL,
    max_step: float = 0.05,
    progress: bool = False,
) -> PlantResponse:
    """Simulate the plant over the sample grid ``time`` [s] with zero-order-hold inputs.

    Parameters
    ----------
    parameters : PlantParameters
    time : array_like, shape (n,)
        Strictly increasing sample instants [s].
    valve_voltage : array_like
        Coil command [V] per sample (a scalar is held constant).
    pump_speed : array_like
        Pump (turbine) speed *command* [r/min] per sample; with droop on, the actual pump speed
        falls with pump pressure and is returned as ``pump_speed_rpm``.
    initial_state : array_like (5,), optional
        x(t_0) in SI. Default: the steady state at the first inputs.
    valve_initial : float, optional
        Output of the play operator before the first sample [V]. Default: the first command
        (the play centred on it).
    rtol : float
        Relative tolerance of the step control.
    max_step : float
        Longest integration step [s].
    progress : bool
        A progress bar (simulated seconds) on a terminal, for a profile longer than
        :data:`PROGRESS_AFTER` seconds.

    Raises
    ------
    SimulationError
        When the integrator fails (step size underflow, non-finite state), with where and why.
    """
    t = np.ascontiguousarray(time, dtype=np.float64).reshape(-1)
    n = t.size
    if n < 1:
        raise DataError("time is empty: give at least one sample instant")
    if not np.all(np.isfinite(t)):
        raise DataError(f"time has a non-finite value (NaN or inf) at row {int(np.argmax(~np.isfinite(t)))}")
    if n > 1 and not np.all(np.diff(t) > 0):
        raise DataError(f"time must be strictly increasing; it is not at row {int(np.argmax(~(np.diff(t) > 0))) + 1}")
    if t[-1] - t[0] > MAX_DURATION_S:  # 1e30 s: numpy warnings, then 'step size underflow'; 1e9 s: hours
        raise DataError(f"time spans {t[-1] - t[0]:.6g} s; a run of the test bed spans at most {MAX_DURATION_S:,.0f} s "
                        f"(11.6 days): give the time in seconds, or split the profile")
    v = _as_signal("valve voltage", valve_voltage, n)
    w_rpm = _as_signal("pump speed", pump_speed, n)
    from hwpts.plant.parameters import check_input_ranges

    check_input_ranges(v, w_rpm, error=DataError)
    v_eff = play_operator(v, parameters.hysteresis_half_width, valve_initial)
    h_cmd = np.ascontiguousarray(spool_position(v_eff, parameters))
    wp_cmd = w_rpm * RAD_S_PER_RPM
    p = parameters.as_array()
    if initial_state is None:
        x0, _ = solve_steady_state(parameters, h_cmd[:1], wp_cmd[:1])
        x0 = x0[0]
    else:
        x0 = np.asarray(initial_state, dtype=float).reshape(-1)
        if x0.shape != (N_STATES,) or not np.all(np.isfinite(x0)):
            raise DataError(f"initial_state must be 5 finite numbers, got {initial_state!r}")
    z0 = np.concatenate([x0, h_cmd[:1]])
    grid, source, rows = _held_grid(t, LONG_HOLD)
    h_grid, wp_grid = np.ascontiguousarray(h_cmd[source]), np.ascontiguousarray(wp_cmd[source])
    out_grid = np.empty((grid.size, _NZ))
    out_grid[0] = z0
    stats = np.zeros(4, dtype=np.int64)
    atol = np.array(DEFAULT_ATOL)
    hstate = np.array([min(1e-3, float(max_step))])
    from tqdm import tqdm

    show = progress and t[-1] - t[0] > PROGRESS_AFTER
    with tqdm(total=round(float(t[-1] - t[0]), 2), desc="plant simulation", unit="s", leave=False,
              disable=None if show else True) as bar:
        for a in range(0, grid.size - 1, CHUNK):
            b = min(a + CHUNK, grid.size - 1)
            failed = _integrate(grid[a:b + 1], h_grid[a:b + 1], wp_grid[a:b + 1], p, out_grid[a].copy(),
                                float(rtol), atol, float(max_step), out_grid[a:b + 1], stats, hstate)
            if failed >= 0:
                k = int(source[a + failed])
                raise SimulationError(
                    f"integration failed between t = {t[k]:.6g} s and {t[k + 1]:.6g} s "
                    f"(step size underflow or non-finite state after {stats[0]} steps); "
                    "check the parameters and inputs, or lower rtol"
                )
            bar.update(round(float(grid[b] - grid[a]), 2))
    out = out_grid[rows]
    state = out[:, :N_STATES]
    wp_actual = pump_speed_actual.py_func(state[:, 0], wp_cmd, p)
    return PlantResponse(
        time=t,
        state=state,
        spool=out[:, N_STATES],
        valve_voltage_v=v,
        effective_voltage_v=v_eff,
        pump_speed_command_rpm=w_rpm,
        pump_speed_rpm=wp_actual * RPM_PER_RAD_S,
        stats=SolverStats(int(stats[0]), int(stats[1]), int(stats[2]), int(stats[3])),
    )


class PlantStepper:
    """The plant advanced one sample at a time, for closed-loop simulation.

    The controller computes its command from what it measured at t_k; :meth:`step` holds that
    command (zero-order hold) over [t_k, t_k + sample_time) with the same compiled ROS2 integrator
    as :func:`simulate_plant`, carrying the state, the spool and the play operator's output from
    one call to the next. A load factor scales the load on shaft A (its constant torque T_cA and
    the generator's slip torque K_g), which is how electric load steps are applied.

    Parameters
    ----------
    parameters : PlantParameters
    sample_time : float
        Length of one step [s].
    valve_voltage, pump_speed : float
        The inputs the plant starts in steady state at: valve command [V] (the play centred on
        it) and pump speed command [r/min].
    """

    def __init__(self, parameters: PlantParameters, sample_time: float, valve_voltage: float, pump_speed: float,
                 rtol: float = DEFAULT_RTOL, max_step: float = 0.05):
        if not (math.isfinite(sample_time) and sample_time > 0):
            raise DataError(f"sample_time must be a positive number of seconds, got {sample_time!r}")
        if not (math.isfinite(valve_voltage) and math.isfinite(pump_speed) and pump_speed >= 0):
            raise DataError(f"initial inputs must be finite with pump speed >= 0, got {valve_voltage!r} V, {pump_speed!r} r/min")
        self.parameters = parameters
        self.sample_time = float(sample_time)
        self._p = parameters.as_array()
        self._base_load = (self._p[_I["motor_a_load_torque"]], self._p[_I["generator_slip_gain"]])
        self._r = parameters.hysteresis_half_width
        self._t = np.array([0.0, self.sample_time])
        self._h = np.zeros(2)
        self._w = np.zeros(2)
        self._out = np.empty((2, _NZ))
        self._stats = np.zeros(4, dtype=np.int64)
        self._atol = np.array(DEFAULT_ATOL)
        self._rtol = float(rtol)
        self._max_step = float(max_step)
        self._hstate = np.zeros(1)
        self.effective_voltage_v = float(valve_voltage)
        h0 = spool_position(np.array([valve_voltage]), parameters)
        x0, _ = solve_steady_state(parameters, h0, np.array([pump_speed * RAD_S_PER_RPM]))
        self._z = np.concatenate([x0[0], h0])
        self.time = 0.0
        self.load_factor = 1.0

    @property
    def state(self) -> np.ndarray:
        """x(t) in SI (a copy)."""
        return self._z[:N_STATES].copy()

    @property
    def motor_a_speed_rpm(self) -> float:
        """Motor A (generator) speed [r/min] now."""
        return float(self._z[3] * RPM_PER_RAD_S)

    def pump_speed_rpm(self, pump_speed_command_rpm: float) -> float:
        """The actual pump speed [r/min] at the present pump pressure (after droop)."""
        return float(pump_speed_actual.py_func(self._z[0], pump_speed_command_rpm * RAD_S_PER_RPM, self._p)
                     * RPM_PER_RAD_S)

    def set_load_factor(self, factor: float) -> None:
        """Scale the load on shaft A (1 = nominal; 1.3 = a +30 % electric load step)."""
        if not (math.isfinite(factor) and factor >= 0):
            raise DataError(f"load factor must be a finite number >= 0, got {factor!r}")
        self.load_factor = float(factor)
        self._p[_I["motor_a_load_torque"]] = self._base_load[0] * factor
        self._p[_I["generator_slip_gain"]] = self._base_load[1] * factor

    def step(self, valve_voltage: float, pump_speed: float) -> None:
        """Hold the valve command [V] and the pump speed command [r/min] over one sample."""
        if not (math.isfinite(valve_voltage) and math.isfinite(pump_speed)):
            raise DataError(f"non-finite input at t = {self.time:.3f} s: {valve_voltage!r} V, {pump_speed!r} r/min")
        r = self._r
        v_eff = min(max(self.effective_voltage_v, valve_voltage - r), valve_voltage + r)
        self.effective_voltage_v = v_eff
        p = self.parameters
        span = p.valve_voltage_closed - p.valve_voltage_open
        self._h[0] = p.spool_stroke * min(max((v_eff - p.valve_voltage_open) / span, 0.0), 1.0)
        self._w[0] = max(pump_speed, 0.0) * RAD_S_PER_RPM
        self._hstate[0] = min(1e-3, self._max_step)  # each sample starts afresh, as it always has
        failed = _integrate(self._t, self._h, self._w, self._p, self._z, self._rtol, self._atol, self._max_step,
                            self._out, self._stats, self._hstate)
        if failed >= 0:
            raise SimulationError(f"integration failed in the sample after t = {self.time:.6g} s "
                                  "(step size underflow or non-finite state)")
        self._z[:] = self._out[1]
        self.time += self.sample_time
