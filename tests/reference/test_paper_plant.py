"""The simulator against every number PLANT.md section 6 takes from the paper."""

import numpy as np
import pytest

from hwpts.plant import PlantParameters, TestBed, steady_state, sweep, validation_case


@pytest.mark.parametrize(
    "voltage, pump, paper_rpm",
    [
        (1.8, 904.0, 1566.0),  # paper eq. (15) point, section V.B
        (2.95, 328.0, 489.5),  # paper eq. (15) point, section V.B
        (1.5, 600.0, 1000.0),  # triangle start, Fig. 10
        (2.375, 600.0, 997.5),  # on the space line (15) at t = 0.5
    ],
)
def test_operating_points_within_3_percent(voltage, pump, paper_rpm):
    s = steady_state(PlantParameters.averaged(), voltage, pump)
    assert float(s.motor_a_speed_rpm) == pytest.approx(paper_rpm, rel=0.03)


def test_motor_a_stops_when_the_valve_closes():
    # paper eq. (18): wA = 0 if hi >= 3.5
    v, w = np.meshgrid(np.linspace(3.5, 3.8, 7), np.linspace(200, 1000, 17))
    s = steady_state(PlantParameters.averaged(), v, w)
    assert np.all(s.motor_a_speed_rpm < 5.0)


def test_branch_b_opens_along_the_fracture_line_eq16():
    # paper eq. (16): wp = -486.41 hi + 1755.2
    p = PlantParameters.averaged()
    v = np.linspace(1.2, 3.8, 1301)
    for pump in np.linspace(200, 1000, 9):
        s = steady_state(p, v, np.full_like(v, pump))
        onset = v[np.argmax(s.motor_b_speed_rpm > 5.0)]
        assert onset == pytest.approx((1755.2 - pump) / 486.41, abs=0.1), pump


def test_space_line_eq15_projects_to_eq16():
    # eq. (15): hi = 1.25 t + 1.75, wp = -608 t + 904; eliminating t gives eq. (16)
    t = np.linspace(-1, 2, 7)
    hi = 1.25 * t + 1.75
    wp = -608 * t + 904
    slope, intercept = np.polyfit(hi, wp, 1)
    assert slope == pytest.approx(-486.41, abs=0.02)  # -608 / 1.25 = -486.40; the paper prints -486.41
    assert intercept == pytest.approx(1755.2, abs=0.1)


def test_triangle_test_fig10():
    # section V.D: motor A 1000 -> ~200 -> 1000 r/min, pump 600 -> ~500 -> 600 r/min
    bed = TestBed(noise_std_rpm=0.0)
    ds, resp = bed.record(validation_case("case3"))
    wa = resp.motor_a_speed_rpm
    wp = resp.pump_speed_rpm
    assert wa[0] == pytest.approx(1000, rel=0.03) and wa[-1] == pytest.approx(1000, rel=0.03)
    assert wa.min() == pytest.approx(200, abs=30)
    assert wp[0] == pytest.approx(600, abs=5) and wp[-1] == pytest.approx(600, abs=10)
    assert wp.min() == pytest.approx(500, abs=15)


def test_up_and_down_sweeps_differ_by_tens_of_percent_fig4():
    result = sweep(PlantParameters.paper(), np.linspace(1.2, 3.8, 27), np.linspace(200, 1000, 81), progress=False)
    gap = result.gap_percent
    assert 20.0 <= gap.max() <= 40.0  # paper Fig. 4: up to ~30 % of full scale
    assert gap.min() >= -1e-6


def test_fracture_line_found_in_the_data_is_close_to_eq16():
    # section V.B: the fracture of the averaged surface (Fig. 5, Fig. 7) projects to eq. (16)
    from hwpts.experiments.sweeps import find_fracture, record_sweeps

    f = find_fracture(record_sweeps(progress=False))
    pumps = np.linspace(200, 1000, 9)
    assert np.max(np.abs(f.voltage_at(pumps) - (1755.2 - pumps) / 486.41)) < 0.1
    assert f.slope == pytest.approx(-486.41, rel=0.1)
