import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hwpts.errors import ParameterError
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.valve import orifice_flow, outlet_areas, play_operator, spool_position

commands = st.lists(st.floats(-10, 10, allow_nan=False), min_size=1, max_size=200)
widths = st.floats(0, 2, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(commands, widths)
def test_play_stays_within_half_width_of_its_input(v, r):
    out = play_operator(v, r)
    assert np.all(np.abs(out - np.asarray(v)) <= r + 1e-12)


@settings(max_examples=100, deadline=None)
@given(commands)
def test_play_is_identity_at_zero_width(v):
    assert np.array_equal(play_operator(v, 0.0), np.asarray(v))


@settings(max_examples=100, deadline=None)
@given(commands, widths, st.floats(-10, 10, allow_nan=False))
def test_play_is_a_pure_function_of_history_and_initial_state(v, r, v0):
    a = play_operator(v, r, initial=v0)
    b = play_operator(v, r, initial=v0)
    assert np.array_equal(a, b)
    # splitting the history and carrying the output over gives the same result
    k = len(v) // 2
    if k:
        first = play_operator(v[:k], r, initial=v0)
        second = play_operator(v[k:], r, initial=first[-1])
        assert np.array_equal(np.concatenate([first, second]), a)


@settings(max_examples=100, deadline=None)
@given(commands, widths)
def test_play_does_not_move_while_the_input_stays_inside_the_band(v, r):
    out = play_operator(v, r)
    moved = np.diff(out) != 0
    # where the output moved, it sits on the edge of the band
    edge = np.isclose(np.abs(out[1:] - np.asarray(v)[1:]), r)
    assert np.all(edge[moved])


def test_play_example_and_loop():
    # a triangle 1.5 -> 3.5 -> 1.5 V: on the way back the output lags by 2r (PLANT.md section 4)
    up = np.linspace(1.5, 3.5, 21)
    v = np.concatenate([up, up[::-1][1:]])
    out = play_operator(v, 0.25)
    assert out.max() == pytest.approx(3.25)
    assert out[-1] == pytest.approx(1.75)


def test_play_rejects_bad_arguments():
    with pytest.raises(ParameterError, match="half_width"):
        play_operator([1.0], -0.1)
    with pytest.raises(ParameterError, match="finite"):
        play_operator([1.0, np.nan], 0.1)


def test_spool_map():
    p = PlantParameters.paper()
    h = spool_position([0.0, 1.2, 2.35, 3.5, 5.0], p)
    assert np.allclose(h / p.spool_stroke, [0, 0, 0.5, 1, 1])
    a_a, a_b = outlet_areas(h, p)
    assert np.allclose(a_a + a_b, p.max_orifice_area + 2 * p.leak_area)


def test_orifice_law_paper_eq_14_and_check_valve():
    p = PlantParameters.paper()
    area = 5e-6
    dp = 1e6
    exact = p.discharge_coefficient * area * np.sqrt(2 * dp / p.oil_density)  # paper eq. (14)
    assert orifice_flow(area, dp, p) == pytest.approx(exact, rel=1e-3)
    assert abs(orifice_flow(area, -1e5, p)) < 1e-3 * exact  # one-way
    q = orifice_flow(area, np.linspace(-1e4, 1e4, 101), p)
    assert np.all(np.diff(q) >= 0)  # monotone through the origin, no jump


def test_the_make_up_valve_opens_only_under_suction():
    # docs/plant.md 2.8: no make-up flow at a positive pressure (a smooth max fed an idle chamber from
    # the tank, uphill), continuous with its slope where it opens
    from hwpts.plant.valve import MAKEUP_ONSET_PA, makeup_shape, makeup_shape_derivative

    w = MAKEUP_ONSET_PA
    assert makeup_shape(-5000.0, w) == 0.0 and makeup_shape(0.0, w) == 0.0
    assert makeup_shape(w, w) == pytest.approx(w / 2) and makeup_shape(3 * w, w) == pytest.approx(2.5 * w)
    for s in (0.3 * w, w, 2 * w):
        fd = (makeup_shape(s + 1e-3, w) - makeup_shape(s - 1e-3, w)) / 2e-3
        assert makeup_shape_derivative(s, w) == pytest.approx(fd, rel=1e-6)
