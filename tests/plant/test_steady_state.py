import numpy as np
import pytest

from hwpts.errors import ParameterError
from hwpts.plant import PlantParameters, steady_state, sweep
from hwpts.plant.dynamics import rhs
from hwpts.plant.steady_state import sweep_effective_voltages
from hwpts.plant.valve import spool_position
from hwpts.units import rpm_to_rad_s


def test_steady_states_are_equilibria_of_the_dynamics():
    p = PlantParameters.test_bed()
    rng = np.random.default_rng(1)
    v = rng.uniform(1.2, 3.8, 40)
    w = rng.uniform(200, 1000, 40)
    s = steady_state(p, v, w)
    for i in range(v.size):
        dx = rhs(p, s.state[i], spool_position(v[i], p), rpm_to_rad_s(w[i]))
        # chamber equations in Pa/s (beta/V ~ 1e13), shafts in rad/s^2
        assert np.all(np.abs(dx[:3]) < 1.0), (v[i], w[i], dx)
        assert np.all(np.abs(dx[3:]) < 1e-6), (v[i], w[i], dx)


def test_vectorised_equals_pointwise_and_keeps_shape():
    p = PlantParameters.averaged()
    v = np.array([[1.5, 2.0], [2.5, 3.0]])
    w = np.array([[400.0, 600.0], [800.0, 1000.0]])
    grid = steady_state(p, v, w)
    assert grid.motor_a_speed_rpm.shape == (2, 2)
    one = steady_state(p, 2.5, 800.0)
    assert grid.motor_a_speed_rpm[1, 0] == pytest.approx(float(one.motor_a_speed_rpm), rel=1e-12)


def test_monotone_in_inputs():
    p = PlantParameters.averaged()
    v = np.linspace(1.2, 3.8, 60)
    s = steady_state(p, v, np.full_like(v, 700.0))
    assert np.all(np.diff(s.motor_a_speed_rpm) <= 1e-6)  # closing A slows motor A
    w = np.linspace(200, 1000, 60)
    s = steady_state(p, np.full_like(w, 2.0), w)
    assert np.all(np.diff(s.motor_a_speed_rpm) >= -1e-6)  # more flow, faster motor A


def test_branches_bracket_the_averaged_valve():
    p = PlantParameters.paper()
    v, w = 2.6, 700.0
    up = steady_state(p, v, w, branch="up").motor_a_speed_rpm
    down = steady_state(p, v, w, branch="down").motor_a_speed_rpm
    none = steady_state(p, v, w, branch="none").motor_a_speed_rpm
    assert up > none > down


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"valve_voltage": np.nan, "pump_speed_rpm": 500}, "valve voltage must be a finite number"),
        ({"valve_voltage": 2.0, "pump_speed_rpm": np.inf}, "pump speed must be a finite number"),
        ({"valve_voltage": 2.0, "pump_speed_rpm": -5.0}, "pump speed must be a finite number in 0-3000 r/min"),
        ({"valve_voltage": 2.0, "pump_speed_rpm": 500, "branch": "sideways"}, "branch must be one of"),
    ],
)
def test_bad_operating_points(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        steady_state(PlantParameters.paper(), **kwargs)


def test_sweep_grid_and_effective_voltages():
    v = np.linspace(1.2, 3.8, 27)
    up, down = sweep_effective_voltages(v, 0.25)
    assert np.allclose(up, v - 0.25) and np.allclose(down, v + 0.25)
    result = sweep(PlantParameters.paper(), v, np.linspace(200, 1000, 81), progress=False)
    assert result.points_per_sweep == 2187  # paper Fig. 3
    assert result.up_rpm.shape == (27, 81)
    assert np.allclose(result.average_rpm, 0.5 * (result.up_rpm + result.down_rpm))
    assert np.all(result.up_rpm >= result.down_rpm - 1e-6)


def test_sweep_rejects_empty_grid():
    with pytest.raises(ParameterError, match="empty"):
        sweep(PlantParameters.paper(), [], [500.0])
