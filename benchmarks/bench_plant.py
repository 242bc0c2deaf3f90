"""Plant speed: the full up+down steady-state sweep and the 60 s case4 simulation.

Baselines, measured in the same run (the straightforward way with SciPy):
- sweep: a per-point ``scipy.optimize.root`` (hybr) of F(x) = 0 with the plain-Python right-hand
  side, each point started from the previous one along the sweep (continuation);
- simulation: ``scipy.integrate.solve_ivp`` LSODA over the whole horizon with the plain-Python
  right-hand side and the zero-order-hold inputs looked up at each call.
The plain-Python right-hand side is the same code as the compiled one (numba's ``py_func``).

Run: ``python -m benchmarks plant`` (``--quick`` times the baselines on a subset and scales up).
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

from hwpts.plant import PlantParameters, simulate_plant, sweep, validation_case
from hwpts.plant.dynamics import N_STATES, rhs_into
from hwpts.plant.steady_state import solve_steady_state, sweep_effective_voltages
from hwpts.plant.valve import play_operator, spool_position
from hwpts.units import RAD_S_PER_RPM, RPM_PER_RAD_S


def _best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


BASELINE_TOL = 1e-8  # largest scaled residual of a baseline root solve counted as solved


def _solved(sol) -> bool:
    return bool(sol.success and np.max(np.abs(sol.fun)) < BASELINE_TOL)  # (root's residual at sol.x)


def _baseline_sweep(params, voltages, pumps, limit=None):
    """Per-point root solve with continuation along each sweep; returns (speeds, failures, n)."""
    p = params.as_array()
    py_rhs = rhs_into.py_func
    up, down = sweep_effective_voltages(voltages, params.hysteresis_half_width)
    speeds, failures, count = [], 0, 0
    x_scale = np.array([1e6, 1e6, 1e6, 100.0, 100.0])
    f_scale = np.array([params.pump_chamber_volume, params.motor_a_chamber_volume, params.motor_b_chamber_volume,
                        0.0, 0.0]) / params.bulk_modulus / 1e-4
    f_scale[3:] = [params.motor_a_inertia, params.motor_b_inertia]
    for direction in (up, down[::-1]):
        for w in pumps:
            wp = w * RAD_S_PER_RPM
            z = np.array([1.0, 0.5, 0.0, 1.0, 0.0])
            for v in direction:
                h = float(spool_position(v, params))

                def f(zz):
                    dx = np.empty(N_STATES)
                    py_rhs(zz * x_scale, h, wp, p, dx)
                    return dx * f_scale

                # a solve counts where its scaled residual is below BASELINE_TOL: root's own
                # ``success`` said yes at a point left 0.8 from a root (hybr's progress test)
                sol = root(f, z, method="hybr")
                if not _solved(sol):  # fall back to Levenberg-Marquardt, then a fresh start
                    sol = root(f, z, method="lm")
                if not _solved(sol):
                    sol = root(f, np.array([2.0, 1.0, 0.4, 1.0, 0.0]), method="lm")
                ok = _solved(sol)
                failures += not ok
                z = sol.x
                speeds.append(z[3] * x_scale[3] * RPM_PER_RAD_S if ok else np.nan)
                count += 1
                if limit and count >= limit:
                    return np.array(speeds), failures, count
    return np.array(speeds), failures, count


def _baseline_simulation(params, profile):
    p = params.as_array()
    py_rhs = rhs_into.py_func
    t = profile.time
    h = spool_position(play_operator(profile.valve_voltage_v, params.hysteresis_half_width), params)
    wp = profile.pump_speed_rpm * RAD_S_PER_RPM
    x0, _ = solve_steady_state(params, h[:1], wp[:1])

    def f(tt, y):
        k = min(max(int(np.searchsorted(t, tt, side="right")) - 1, 0), t.size - 1)
        dx = np.empty(N_STATES)
        py_rhs(y, h[k], wp[k], p, dx)
        return dx

    sol = solve_ivp(f, (t[0], t[-1]), x0[0], method="LSODA", t_eval=t, rtol=1e-5,
                    atol=[50.0, 50.0, 50.0, 1e-3, 1e-3])
    return sol


def main(argv=None) -> int:
    argv = argv or []
    quick = "--quick" in argv
    params = PlantParameters.paper()
    voltages = np.linspace(1.2, 3.8, 27)
    pumps = np.linspace(200, 1000, 81)
    rows = []

    # -- sweep -----------------------------------------------------------------------------
    t0 = time.perf_counter()
    sweep(params, voltages, pumps, progress=False)
    first = time.perf_counter() - t0
    ours, result = _best_of(lambda: sweep(params, voltages, pumps, progress=False), 5)
    limit = 400 if quick else None
    t0 = time.perf_counter()
    speeds, failures, count = _baseline_sweep(params, voltages, pumps, limit)
    base = (time.perf_counter() - t0) * (2 * voltages.size * pumps.size / count)
    ref = np.concatenate([result.up_rpm.T.ravel(), result.down_rpm[::-1].T.ravel()])[:count]
    agree = np.abs(speeds - ref)[np.isfinite(speeds)]
    rows.append(("up+down sweep, 2 x 2187 points", ours, first, base, 2.0,
                 f"baseline: {failures} of {count} root solves failed (residual above {BASELINE_TOL:g}); "
                 f"max |diff| {np.max(agree, initial=0.0):.2g} r/min where they did"
                 + (" (baseline timed on a subset, scaled)" if limit else "")))

    # -- case4 simulation ------------------------------------------------------------------
    bed = PlantParameters.test_bed()
    profile = validation_case("case4", sample_time=0.01)

    def run_ours():
        return simulate_plant(bed, profile.time, profile.valve_voltage_v, profile.pump_speed_rpm)

    t0 = time.perf_counter()
    run_ours()
    first = time.perf_counter() - t0
    ours, sim = _best_of(run_ours, 5)
    t0 = time.perf_counter()
    sol = _baseline_simulation(bed, profile)
    base = time.perf_counter() - t0
    if sol.success:
        diff = np.max(np.abs(sol.y[3] - sim.state[:, 3])) * RPM_PER_RAD_S
        note = f"LSODA {sol.nfev} rhs calls; ours {sim.stats.steps} steps; max |diff| {diff:.2g} r/min"
    else:
        note = f"LSODA failed: {sol.message}"
    rows.append(("case4 simulation, 60 s at 10 ms", ours, first, base, 0.5, note))

    print(f"{'task':34s} {'ours [s]':>9s} {'1st call':>9s} {'baseline [s]':>13s} {'speed-up':>9s} {'target':>8s}")
    status = 0
    for name, ours_s, first_s, base_s, target, note in rows:
        ok = ours_s <= target
        status |= not ok
        print(f"{name:34s} {ours_s:9.3f} {first_s:9.3f} {base_s:13.2f} {base_s / ours_s:8.0f}x "
              f"{'<= ' + format(target, 'g') + ' s':>8s} {'ok' if ok else 'MISSED'}")
        print(f"    {note}")
    print("ours = median of 5 warm runs; 1st call includes loading the compiled kernels from numba's cache")
    return 0 if status == 0 else 1
