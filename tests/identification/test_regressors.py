"""Regression vectors (paper eqs. 6-7)."""

import numpy as np
import pytest

from hwpts.errors import DataError, ParameterError
from hwpts.identification.regressors import RegressorStructure


def test_columns_follow_eq7_with_delay():
    st = RegressorStructure.create(2, [2, 1], [1, 0], 2, input_names=["h", "w"], output_name="y")
    assert st.feature_names == ["y(k-1)", "y(k-2)", "h(k-1)", "h(k-2)", "w(k)"]
    assert st.max_lag == 2 and st.n_parameters == 6
    u = np.column_stack([np.arange(10.0), 100 + np.arange(10.0)])
    y = 1000 + np.arange(10.0)
    X, t = st.build(u, y)
    assert X.shape == (8, 5)
    # row for k = 2: y(1), y(0), h(1), h(0), w(2)
    np.testing.assert_array_equal(X[0], [1001, 1000, 1, 0, 102])
    assert t[0] == 1002


def test_paper_eq18_uses_current_input():
    st = RegressorStructure.create(5, 4, 0, 2, input_names=["hi", "wp"], output_name="wmA")
    assert st.feature_names[5:9] == ["hi(k)", "hi(k-1)", "hi(k-2)", "hi(k-3)"]
    assert st.max_lag == 5


def test_extended_regressor_has_constant():
    st = RegressorStructure.create(1, 1, 1, 1)
    X = np.ones((3, 2))
    assert st.extend(X).shape == (3, 3)
    assert RegressorStructure.create(1, 1, 1, 1, constant=False).extend(X).shape == (3, 2)


def test_too_short_names_the_need():
    st = RegressorStructure.create(5, 4, 0, 2)
    with pytest.raises(DataError, match=r"na=5, nb=4, nk=0 needs at least 19 samples .*the data has 7 rows"):
        st.build(np.zeros((7, 2)), np.zeros(7))


@pytest.mark.parametrize("kwargs, match", [
    ({"na": -1, "nb": 1, "nk": 1}, "na"),
    ({"na": 1, "nb": [1, 2, 3], "nk": 1}, "3 entries but there are 2 inputs"),
    ({"na": 1, "nb": 1, "nk": -1}, "nk"),
    ({"na": 0, "nb": 0, "nk": 1}, "empty regressor"),
])
def test_bad_orders(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        RegressorStructure.create(n_inputs=2, **kwargs)


def test_column_index_by_input_name():
    st = RegressorStructure.create(2, 2, 1, 2, input_names=["a", "b"])
    assert st.column_index("b") == st.feature_names.index("b(k-1)")
    assert st.column_index("a(k-2)") == 3
    with pytest.raises(ParameterError, match="unknown regressor column 'c'"):
        st.column_index("c")


def test_a_name_that_means_two_columns_is_refused_not_guessed():
    """An input named ``y(k-1)`` beside the output ``y``: the name is both the output's lag and the
    input; a hyperplane or partition column by that name is refused, one given by position is the input's."""
    from hwpts.identification.partition import Hyperplane

    st = RegressorStructure.create(1, 1, 1, 1, input_names=["y(k-1)"], output_name="y")
    assert st.feature_names == ["y(k-1)", "y(k-1)(k-1)"]
    with pytest.raises(ParameterError, match="'y\\(k-1\\)' is ambiguous: it names the regressor column"):
        st.column_index("y(k-1)")
    assert st.column_index("y(k-1)(k-1)") == 1 and st.column_index("y") == 0
    a, _ = Hyperplane([1.0], 0.0).resolve(st)  # on the first input, by position
    np.testing.assert_array_equal(a, [0.0, 1.0])
    # an output named as an input's lag
    st = RegressorStructure.create(1, 1, 1, 1, input_names=["u"], output_name="u(k-1)")
    with pytest.raises(ParameterError, match="ambiguous"):
        st.column_index("u(k-1)")


@pytest.mark.parametrize("bad", [[True], {1}, [1.0], 2.0, "1"])
def test_per_input_orders_are_ints_as_the_scalar_ones(bad):
    """[True], {1} and [1.0] were taken while 2.0 was refused (and a set has no input order)."""
    with pytest.raises(ParameterError, match=r"nb \(input order\) must be an int or a list of ints \(one per input\)"):
        RegressorStructure.create(1, bad, 1, 1)
    assert RegressorStructure.create(1, np.array([2]), [np.int32(1)], 1).nb == (2,)
