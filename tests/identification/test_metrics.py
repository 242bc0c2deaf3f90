"""Fit %, RMSE, region accuracy with the best permutation, parameter error."""

import numpy as np
import pytest

from hwpts.errors import DataError
from hwpts.identification.metrics import fit_percent, parameter_error, region_accuracy, rmse


def test_fit_percent_definition():
    y = np.array([1.0, 2.0, 3.0, 4.0])
    assert fit_percent(y, y) == 100.0
    assert fit_percent(y, np.full(4, y.mean())) == pytest.approx(0.0)
    yhat = y + np.array([0.1, -0.1, 0.1, -0.1])
    expected = 100 * (1 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean()))
    assert fit_percent(y, yhat) == pytest.approx(expected)
    assert np.isnan(fit_percent(y, [1, 2, np.inf, 4]))
    assert rmse(y, yhat) == pytest.approx(0.1)


def test_fit_of_constant_output_is_undefined():
    with pytest.raises(DataError, match="constant"):
        fit_percent([2.0, 2.0], [2.0, 2.0])


def test_region_accuracy_best_permutation():
    true = np.array([0, 0, 1, 1, 2, 2])
    est = np.array([2, 2, 0, 0, 1, 0])
    assert region_accuracy(true, est) == pytest.approx(5 / 6)


def test_parameter_error_matches_modes():
    T = np.array([[1.0, 0.0], [0.0, 2.0]])
    E = np.array([[0.0, 2.2], [1.0, 0.1]])
    assert parameter_error(T, E) == pytest.approx(0.1)
