import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hwpts.errors import DataError, SimulationError
from hwpts.plant import PlantParameters, simulate_plant, steady_state, validation_case
from hwpts.plant.dynamics import jacobian, rhs
from hwpts.plant.valve import play_operator, spool_position
from hwpts.units import RPM_PER_RAD_S, rpm_to_rad_s


def _radau_reference(p, t, v, w_rpm, x0):
    h = spool_position(play_operator(v, p.hysteresis_half_width), p)
    x = x0.copy()
    out = [x]
    for k in range(t.size - 1):
        args = (h[k], rpm_to_rad_s(w_rpm[k]))
        sol = solve_ivp(
            lambda _, y, hk, wk: rhs(p, y, hk, wk), (t[k], t[k + 1]), x, method="Radau",
            jac=lambda _, y, hk, wk: jacobian(p, y, hk, wk)[0], rtol=1e-9,
            atol=[1e-3, 1e-3, 1e-3, 1e-7, 1e-7], args=args,
        )
        x = sol.y[:, -1]
        out.append(x)
    return np.array(out)


def test_matches_a_tight_radau_solution():
    p = PlantParameters.test_bed()
    t = np.arange(0, 3.0, 0.01)
    v = np.where(t < 1.0, 1.8, np.where(t < 2.0, 3.3, 2.4))
    w = np.where(t < 1.5, 650.0, 850.0)
    sim = simulate_plant(p, t, v, w)
    ref = _radau_reference(p, t, v, w, sim.state[0])
    err_rpm = np.abs(ref[:, 3] - sim.state[:, 3]) * RPM_PER_RAD_S
    assert err_rpm.max() < 0.5  # r/min, on a response spanning hundreds of r/min
    assert np.abs(ref[:, 0] - sim.state[:, 0]).max() < 2e3  # Pa, on MPa pressures


def test_starts_at_steady_state_and_stays_there():
    p = PlantParameters.averaged()
    t = np.arange(0, 2.0, 0.01)
    sim = simulate_plant(p, t, 2.2, 700.0)
    s = steady_state(p, 2.2, 700.0)
    assert np.allclose(sim.motor_a_speed_rpm, float(s.motor_a_speed_rpm), atol=1e-3)


def test_stiffness_budget_case4():
    # SciPy's test_ivp counts evaluations the same way: the solver's work on a standard profile.
    # An explicit RK45 needs ~1e5 steps per 10 s of this model (PLANT.md section 7).
    profile = validation_case("case4")
    sim = simulate_plant(PlantParameters.test_bed(), profile.time, profile.valve_voltage_v, profile.pump_speed_rpm)
    assert sim.stats.steps < 60_000
    assert sim.stats.rhs_evaluations < 150_000
    assert sim.stats.jacobian_evaluations < 80_000


def test_spool_lag_adds_a_smooth_sixth_state():
    p = PlantParameters.averaged().replace(spool_time_constant=0.03)
    t = np.arange(0, 0.5, 0.005)
    v = np.where(t < 0.1, 1.5, 3.0)
    sim = simulate_plant(p, t, v, 700.0)
    target = float(spool_position(3.0, p))
    k = np.searchsorted(t, 0.1 + 0.03)  # one time constant after the step
    assert sim.spool[k] == pytest.approx(float(spool_position(1.5, p)) + (1 - np.exp(-1)) * (target - float(spool_position(1.5, p))), rel=0.02)
    assert sim.spool[-1] == pytest.approx(target, rel=1e-3)


def test_solver_failure_raises_simulation_error():
    t = np.arange(0, 0.05, 0.01)
    with pytest.raises(SimulationError, match="integration failed between t = 0 s"):
        simulate_plant(PlantParameters.paper(), t, 2.0, 500.0, max_step=1e-9)


@pytest.mark.parametrize(
    "time, v, w, match",
    [
        ([0.0, 0.1, 0.1], 2.0, 500.0, "strictly increasing"),
        ([0.0, np.nan], 2.0, 500.0, "time has a non-finite"),
        ([0.0, 0.1], [2.0, np.nan], 500.0, "valve voltage has a non-finite"),
        ([0.0, 0.1], 2.0, [500.0, -1.0], "pump speed must be a finite number in 0-3000 r/min"),
        ([], 2.0, 500.0, "time is empty"),
        # 1e30 s printed numpy warnings, then 'step size underflow'; 1e17 'not enough memory'
        ([0.0, 1e30], 2.0, 500.0, "time spans 1e\\+30 s; a run of the test bed spans at most 1,000,000 s"),
        ([0.0, 1e17], 2.0, 500.0, "spans at most 1,000,000 s"),
    ],
)
def test_bad_inputs(time, v, w, match):
    with pytest.raises(DataError, match=match):
        simulate_plant(PlantParameters.paper(), time, v, w)


def test_two_rows_far_apart_are_integrated():
    """6000 s of constant inputs between two rows needs 120,000 steps of the 0.05 s maximum: the
    per-interval guard of 100,000 steps called it a solver failure ('lower rtol')."""
    sim = simulate_plant(PlantParameters.paper(), np.array([0.0, 6000.0]), 2.4, 700.0)
    assert np.all(np.isfinite(sim.motor_a_speed_rpm))


def test_a_grid_integrated_in_chunks_steps_as_in_one_piece(monkeypatch):
    """The grid is integrated CHUNK intervals at a time (Python's signal handlers run between two
    calls of the compiled loop: a profile of 10^6 s ignored Ctrl-C until it ended), the step size
    carried from one call to the next: chunks of 7 intervals give case 3 bit for bit."""
    from hwpts.plant import simulate as S

    case = validation_case("case3")
    whole = simulate_plant(PlantParameters.paper(), case.time, case.valve_voltage_v, case.pump_speed_rpm)
    monkeypatch.setattr(S, "CHUNK", 7)
    chunked = simulate_plant(PlantParameters.paper(), case.time, case.valve_voltage_v, case.pump_speed_rpm)
    np.testing.assert_array_equal(chunked.state, whole.state)
    assert chunked.stats == whole.stats


def test_a_long_hold_is_cut_into_pieces_and_the_rows_kept():
    """A hold longer than LONG_HOLD is integrated in pieces of at most that length (each a chunk
    boundary where a signal can land); the response is given at the rows of ``time`` only, and a
    25 s hold agrees with the same hold given as rows 1 s apart to the solver's tolerance."""
    from hwpts.plant.simulate import LONG_HOLD, _held_grid

    t = np.array([0.0, 0.5, 25.5, 26.0])
    grid, source, rows = _held_grid(t, LONG_HOLD)
    np.testing.assert_array_equal(grid[rows], t)
    assert np.max(np.diff(grid)) <= LONG_HOLD
    np.testing.assert_array_equal(source[rows], np.arange(4))
    assert np.all(t[source] <= grid) and np.all(np.diff(source) >= 0)
    v, w = np.array([2.4, 3.2, 2.6, 2.6]), np.array([700.0, 700.0, 800.0, 800.0])
    sim = simulate_plant(PlantParameters.paper(), t, v, w)
    assert sim.state.shape == (4, 5)
    fine = np.r_[0.0, np.arange(0.5, 25.5, 1.0), 25.5, 26.0]
    rows = np.searchsorted(fine, t)
    held = np.searchsorted(t, fine, side="right") - 1  # the row whose inputs hold at each fine instant
    ref = simulate_plant(PlantParameters.paper(), fine, v[held], w[held])
    np.testing.assert_allclose(sim.motor_a_speed_rpm, ref.motor_a_speed_rpm[rows], rtol=1e-4)


def test_an_abrupt_stop_keeps_the_pump_forward_and_the_pressures_above_vacuum():
    # docs/plant.md 2.8-2.9: full flow to motor B (10 V, 3000 r/min), then valve and pump command to 0:
    # the make-up valves feed the chambers that motor B and motor A empty as they coast (a gain of 1e-9
    # let P_B fall to -574 kPa, below vacuum) and the pump stops instead of running at -577 r/min
    p = PlantParameters.test_bed()
    t = np.arange(0, 6.0, 0.01)
    on = t < 2.0
    sim = simulate_plant(p, t, np.where(on, 10.0, 0.0), np.where(on, 3000.0, 0.0))
    assert sim.motor_b_speed_rpm[on].max() > 4000
    assert sim.pump_speed_rpm.min() >= 0.0
    assert sim.state[:, :3].min() > -2e3  # Pa gauge (-1.06 kPa here): vacuum is -101 kPa


def test_a_coasting_motor_held_by_its_make_up_valve_costs_the_solver_nothing():
    # 3.0 V / 600 r/min -> 2.4 V / 200 r/min on 50 ms rows: motor B coasts with its inlet held near 0
    # by the make-up valve. A make-up flow switching over 10 Pa (under the 50 Pa tolerance) with a gain
    # of 1e-6 failed here ("step size underflow" after 92,834 steps); 10 ms rows took 44,519 steps
    p = PlantParameters.test_bed()
    for dt in (0.01, 0.05):
        t = np.arange(0, 2 + dt / 2, dt)
        sim = simulate_plant(p, t, np.where(t < 1, 3.0, 2.4), np.where(t < 1, 600.0, 200.0))
        assert sim.stats.steps < 2000
        assert sim.state[:, :3].min() > -1e3


def test_the_relief_valve_holds_the_pump_line_near_its_setting():
    # full pump flow through the relief valve (10 V, 3000 r/min): a relief gain of 1e-10 needed 7.8 MPa
    # above the 6.9 MPa setting to pass it (steady 8.14 MPa, a step peaked at 11.2 MPa)
    p = PlantParameters.test_bed()
    s = steady_state(p, 10.0, 3000.0)
    assert float(s.pump_pressure_pa) < 1.05 * p.relief_pressure
    t = np.arange(0, 2.0, 0.01)
    sim = simulate_plant(p, t, np.where(t < 0.5, 1.2, 10.0), 3000.0)
    assert sim.pump_pressure_pa.max() < 1.15 * p.relief_pressure
