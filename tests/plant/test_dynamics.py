import numpy as np
import pytest

from hwpts.plant import PlantParameters, steady_state
from hwpts.plant.dynamics import jacobian, paper_form, rhs, transfer_poles_zeros
from hwpts.plant.valve import spool_position
from hwpts.units import rpm_to_rad_s

POINTS = [(1.5, 600.0), (1.8, 904.0), (2.375, 600.0), (2.95, 328.0), (3.2, 900.0), (2.0, 300.0)]


def _operating_point(p, v, w):
    s = steady_state(p, v, w)
    return s.state, float(spool_position(v, p)), rpm_to_rad_s(w)


@pytest.mark.parametrize("v, w", POINTS)
def test_jacobian_matches_finite_differences(v, w):
    p = PlantParameters.test_bed()  # droop on exercises that term too
    x, h, wp = _operating_point(p, v, w)
    x = x * np.array([1.01, 0.99, 1.02, 0.98, 1.0]) + np.array([0, 0, 0, 0, 2.0])
    jac, dfdh = jacobian(p, x, h, wp)
    step = np.array([10.0, 10.0, 10.0, 1e-4, 1e-4])
    fd = np.empty((5, 5))
    for j in range(5):
        e = np.zeros(5)
        e[j] = step[j]
        fd[:, j] = (rhs(p, x + e, h, wp) - rhs(p, x - e, h, wp)) / (2 * step[j])
    scale = np.abs(fd).max(axis=1, keepdims=True) + 1e-12
    assert np.max(np.abs(jac - fd) / scale) < 1e-5
    dh = 1e-9
    fd_h = (rhs(p, x, h + dh, wp) - rhs(p, x, h - dh, wp)) / (2 * dh)
    assert np.allclose(dfdh, fd_h, rtol=1e-4, atol=1e-6 * np.abs(fd_h).max())


def test_paper_form_equals_full_model_away_from_the_regularisation():
    # PLANT.md section 3: x' = f(x) + g(x) U when droop is off and orifice drops >> p_cr
    p = PlantParameters.paper().replace(leak_area=0.0)  # the paper form has no leak area
    x = np.array([3.0e6, 1.0e6, 4.0e5, 150.0, 40.0])  # both branches flowing with large drops
    u = np.array([0.4e-3, 90.0])
    f, g = paper_form(p, x)
    full = rhs(p, x, u[0], u[1])
    gross = np.abs(f) + np.abs(g) @ np.abs(u)  # the net rates are differences of large flows
    assert np.all(np.abs(f + g @ u - full) <= 5e-4 * gross)  # the p_cr regularisation: (p_cr/dP)^2/4


@pytest.mark.parametrize("v, w", POINTS)
def test_five_poles_three_zeros(v, w):
    # paper section V.C: "five poles and three zeros", behind na = 5 and nb = 4
    p = PlantParameters.averaged()
    x, h, wp = _operating_point(p, v, w)
    poles, zeros = transfer_poles_zeros(p, x, h, wp)
    assert poles.size == 5
    assert np.all(poles.real < 0), "the operating point must be stable"
    assert zeros.size == 3


def test_a_stopped_pump_does_not_turn_backwards_and_its_jacobian_says_so():
    # docs/plant.md 2.9: w_p = max(w_p,cmd - K_droop D_p P_p, 0); at a command of 100 r/min and
    # 7 MPa the droop alone would give about -475 r/min
    p = PlantParameters.test_bed()
    x = np.array([7.0e6, 3.0e6, 0.9e6, 50.0, 300.0])
    h, wp = float(spool_position(2.0, p)), rpm_to_rad_s(100.0)
    flow = rhs(p, x, h, wp)[0] * p.pump_chamber_volume / p.bulk_modulus
    stopped = rhs(p, x, h, 0.0)[0] * p.pump_chamber_volume / p.bulk_modulus
    assert flow == pytest.approx(stopped)  # no pump flow either way once the droop reaches the command
    jac, _ = jacobian(p, x, h, wp)
    step = 10.0
    e = np.array([step, 0, 0, 0, 0])
    fd = (rhs(p, x + e, h, wp) - rhs(p, x - e, h, wp)) / (2 * step)
    assert np.allclose(jac[:, 0], fd, rtol=1e-5, atol=1e-9 * np.abs(fd).max())
