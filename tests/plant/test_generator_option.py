"""The induction-generator load option and the sample-by-sample stepper."""

import numpy as np
import pytest

from hwpts.plant import PlantParameters, PlantStepper, simulate_plant, steady_state


def test_generator_is_off_by_default_and_loads_shaft_a_when_on():
    p = PlantParameters.test_bed()
    assert p.generator_slip_gain == 0.0
    base = steady_state(p, 2.4, 900.0).motor_a_speed_rpm
    on = p.replace(generator_slip_gain=0.02)
    loaded = steady_state(on, 2.4, 900.0)
    w_sync = on.generator_synchronous_speed
    # the steady state balances the extra slip torque K_g (w_A - w_sync) on shaft A
    wa = loaded.state[3]
    torque = on.motor_a_displacement * loaded.state[1] - on.motor_a_damping * wa \
        - on.motor_a_load_torque * np.tanh(wa / on.coulomb_speed_width) - on.generator_slip_gain * (wa - w_sync)
    assert abs(torque) < 1e-9
    assert (loaded.motor_a_speed_rpm - 1000.0) * (base - 1000.0) > 0  # pulled toward synchronous speed
    assert abs(loaded.motor_a_speed_rpm - 1000.0) < abs(base - 1000.0)


def test_stepper_matches_the_batch_simulation():
    p = PlantParameters.test_bed().replace(generator_slip_gain=0.005)
    n = 400
    t = np.arange(n + 1) * 0.01
    v = 2.4 + 0.4 * np.sin(2 * np.pi * 0.5 * t)
    w = np.where(t < 2.0, 900.0, 800.0)
    batch = simulate_plant(p, t, v, w)
    stepper = PlantStepper(p, 0.01, v[0], w[0])
    y = []
    for k in range(n):
        y.append(stepper.motor_a_speed_rpm)
        stepper.step(v[k], w[k])
    assert np.max(np.abs(np.array(y) - batch.motor_a_speed_rpm[:n])) < 0.05  # r/min
    assert stepper.effective_voltage_v == pytest.approx(batch.effective_voltage_v[n - 1])


def test_load_factor_scales_the_shaft_a_load():
    p = PlantParameters.test_bed().replace(generator_slip_gain=0.005)
    s = PlantStepper(p, 0.01, 2.4, 900.0)
    y0 = s.motor_a_speed_rpm
    s.set_load_factor(1.3)
    for _ in range(300):
        s.step(2.4, 900.0)
    assert s.motor_a_speed_rpm < y0 - 5.0  # +30 % electric load slows the generator
