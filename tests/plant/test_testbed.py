import numpy as np
import pytest

from hwpts.errors import ParameterError
from hwpts.plant import CASE_NAMES, TestBed, identification_excitation, validation_case


@pytest.fixture(scope="module")
def case1_runs():
    bed = TestBed()
    return bed, [bed.record(validation_case("case1"), seed=s)[0] for s in (7, 7, 8)]


def test_same_seed_same_data(case1_runs):
    _, (a, b, c) = case1_runs
    assert np.array_equal(a.output, b.output) and np.array_equal(a.inputs, b.inputs)
    assert not np.array_equal(a.output, c.output)


def test_records_like_the_rig(case1_runs):
    bed, (a, _, _) = case1_runs
    assert a.input_names == ("valve_voltage_v", "pump_speed_rpm")
    assert a.output_name == "motor_a_speed_rpm"
    assert a.sample_time == pytest.approx(bed.sample_time)
    # the measured pump speed is the drooped one, not the command
    assert np.all(a.extra["pump_speed_true_rpm"] < a.extra["pump_speed_command_rpm"])
    noise = a.output - a.extra["motor_a_speed_true_rpm"]
    assert noise.std() == pytest.approx(bed.noise_std_rpm, rel=0.1)


def test_noise_free_bed():
    ds, _ = TestBed(noise_std_rpm=0.0).record(validation_case("case1", sample_time=0.05))
    assert np.array_equal(ds.output, ds.extra["motor_a_speed_true_rpm"])


def test_resamples_a_profile_to_its_own_period():
    ds, _ = TestBed(sample_time=0.05).record(validation_case("case2", sample_time=0.01))
    assert ds.sample_time == pytest.approx(0.05)


def test_bad_settings():
    with pytest.raises(ParameterError, match="sample_time"):
        TestBed(sample_time=0.0)
    with pytest.raises(ParameterError, match="noise_std_rpm"):
        TestBed(noise_std_rpm=-1.0)


@pytest.mark.parametrize("name", CASE_NAMES)
def test_cases_are_uniform_and_in_range(name):
    prof = validation_case(name)
    assert np.allclose(np.diff(prof.time), 0.01)
    assert np.all((prof.valve_voltage_v >= 1.2) & (prof.valve_voltage_v <= 3.8))
    assert np.all((prof.pump_speed_rpm >= 200) & (prof.pump_speed_rpm <= 1000))


def test_case_shapes_follow_the_paper():
    assert np.ptp(validation_case("case1").valve_voltage_v) == 0  # constant valve
    assert np.ptp(validation_case("case1").pump_speed_rpm) > 0  # pump step
    c2 = validation_case("case2").valve_voltage_v
    assert set(np.unique(c2)) == {1.2, 3.8}  # fully open <-> fully closed
    c3 = validation_case("case3").valve_voltage_v
    assert c3.min() == pytest.approx(1.5) and c3.max() == pytest.approx(3.5)
    c4 = validation_case("case4")
    assert len(np.unique(c4.pump_speed_rpm)) == 4 and len(np.unique(np.round(c4.valve_voltage_v, 6))) > 100


def test_identification_excitation_covers_the_range_and_is_seeded():
    a = identification_excitation(duration=300, seed=3)
    b = identification_excitation(duration=300, seed=3)
    assert np.array_equal(a.valve_voltage_v, b.valve_voltage_v)
    assert a.valve_voltage_v.min() == pytest.approx(1.2) and a.valve_voltage_v.max() == pytest.approx(3.8)
    assert a.pump_speed_rpm.min() == pytest.approx(200) and a.pump_speed_rpm.max() == pytest.approx(1000)
    assert len(np.unique(a.valve_voltage_v)) >= 10
