"""Closed-loop control: is sample-by-sample simulation fast enough for 10-minute records, and how long
does each controller take per 10 ms step?

1. The plant stepped one 10 ms sample at a time (:class:`hwpts.plant.PlantStepper`, what the closed
   loop needs) against the batch simulation of the same 10-minute input record (``simulate_plant``,
   the baseline), with the largest speed difference between the two.
2. Every controller on IEC class A turbulence (600 s): controller time per step, median and max,
   against the 10 ms sample; and the whole closed loop's wall time.

Run: ``python -m benchmarks control``.
"""

from __future__ import annotations

import time

import numpy as np


def main(argv=None) -> int:
    from hwpts.commands.control import identify_model_bank
    from hwpts.control.controllers import make_controller
    from hwpts.control.loop import reachable_mask, run_loop
    from hwpts.control.model import ModelBank
    from hwpts.control.scenarios import build_scenario
    from hwpts.io.models import model_to_dict
    from hwpts.plant import PlantStepper, simulate_plant

    status = 0
    sc = build_scenario("turbulence-a", seed=0)
    p = sc.parameters
    n = sc.time.size - 1
    v = 2.45 + 0.2 * np.sin(2 * np.pi * 0.2 * sc.time)
    w = sc.pump_command_rpm
    PlantStepper(p, 0.01, v[0], w[0]).step(v[0], w[0])  # compile / load the kernels
    simulate_plant(p, sc.time[:10], v[:10], w[:10])
    t0 = time.perf_counter()
    batch = simulate_plant(p, sc.time, v, w)
    t_batch = time.perf_counter() - t0
    stepper = PlantStepper(p, 0.01, v[0], w[0])
    y = np.empty(n)
    t0 = time.perf_counter()
    for k in range(n):
        y[k] = stepper.motor_a_speed_rpm
        stepper.step(v[k], w[k])
    t_step = time.perf_counter() - t0
    diff = np.max(np.abs(y - batch.motor_a_speed_rpm[:n]))
    print(f"plant, 600 s record ({n} samples of 10 ms)")
    print(f"  batch simulate_plant (baseline)   {t_batch:7.2f} s  {t_batch / n * 1e6:7.1f} us/sample")
    print(f"  PlantStepper, one sample per call {t_step:7.2f} s  {t_step / n * 1e6:7.1f} us/sample  "
          f"ratio {t_step / t_batch:.2f} x baseline, max |difference| {diff:.4f} r/min")
    model, r_hat, ts = identify_model_bank(seed=0)
    bank = ModelBank(model_to_dict(model), ts)
    reach = reachable_mask(sc)
    print("\ncontrollers on turbulence-a, 600 s: controller time per step [ms] (budget: the 10 ms sample)")
    print(f"  {'controller':22s} {'median':>8s} {'max':>8s} {'loop wall [s]':>14s}")
    for name in ("pi", "scheduled", "mmac", "mpc", "reference"):
        c = make_controller(name, bank, r_hat, sc)
        t0 = time.perf_counter()
        r = run_loop(sc, c, reachable=reach)
        wall = time.perf_counter() - t0
        med, mx = float(np.median(r.step_time_ms)), float(np.max(r.step_time_ms))
        ok = med <= 10.0 and mx <= 50.0
        status |= not ok
        print(f"  {name:22s} {med:8.4f} {mx:8.3f} {wall:14.2f}  {'ok' if ok else 'MISSED'}")
    print("\nhybrid-mpc (MILP, scipy.optimize.milp / HiGHS, every 10 ms sample) on pump-step, load-step and 60 s of "
          "turbulence-a: controller time per step [ms] (target: median <= 10, max <= 50; no failed solve)")
    times, failed, solves = [], 0, 0
    for name, duration in (("pump-step", None), ("load-step", None), ("turbulence-a", 60.0)):
        s = build_scenario(name, seed=0, duration=duration)
        c = make_controller("hybrid-mpc", bank, r_hat, s)
        r = run_loop(s, c)
        times.append(r.step_time_ms)
        failed += c.failed_solves
        solves += c.solves
    t = np.concatenate(times)
    med, mx = float(np.median(t)), float(np.max(t))
    ok = med <= 10.0 and mx <= 50.0 and failed == 0
    status |= not ok
    print(f"  {'hybrid-mpc':22s} {med:8.3f} {mx:8.3f}  p99 {np.percentile(t, 99):.3f}  solves {solves}, failed {failed}  "
          f"{'ok' if ok else 'MISSED'}")
    return status
