"""Fit %, RMSE, region accuracy with the best permutation, parameter error."""

import numpy as np
import pytest

from hwpts.errors import DataError
from hwpts.identification.metrics import (fit_percent, held_out_fit, output_spread, parameter_error,
                                          region_accuracy, rmse)


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


def test_region_accuracy_leaves_out_samples_without_a_true_region():
    """-1 is "no region" (the initial conditions of predict_regions and of the zoo's modes): it
    wrapped to the last region and counted as a miss (0.5 for identical labels)."""
    assert region_accuracy([-1, -1, 0, 1], [-1, -1, 0, 1]) == 1.0
    assert region_accuracy([-1, -1, 0, 0, 1], [-1, -1, 1, 1, 0]) == 1.0
    assert region_accuracy([0, 0, 1], [0, -1, 1]) == pytest.approx(2 / 3)  # no region where one exists: a miss
    with pytest.raises(DataError, match="no sample has a true region"):
        region_accuracy([-1, -1], [0, 1])
    with pytest.raises(DataError, match="whole region numbers"):
        region_accuracy([np.nan, 1], [0, 1])


def test_scores_refuse_what_they_cannot_score_and_do_not_overflow():
    assert fit_percent([0, 1e160, -1e160], [0, 1.1e160, -1e160]) == pytest.approx(fit_percent([0, 1, -1], [0, 1.1, -1]))
    assert fit_percent(np.array([[1.0], [2.0], [3.0]]), [1.0, 2.0, 3.5]) == pytest.approx(64.645, abs=1e-3)
    with pytest.raises(DataError, match="complex"):
        fit_percent(np.array([1 + 5j, 2]), [1, 2])
    with pytest.raises(DataError, match=r"one signal \(1-D\), got shape \(2, 2\)"):
        fit_percent([[1, 2], [3, 4]], [1, 2, 3, 4])
    with pytest.raises(DataError, match="must hold numbers"):
        fit_percent(["a", "b"], [1, 2])
    with pytest.raises(DataError, match="theta_true must be a finite"):
        parameter_error([[1.0, np.nan]], [[1.0, 2.0]])
    with pytest.raises(DataError, match="beyond"):
        parameter_error([[1.0, 2.0]], [[1.0, 2.0]], [0, 3], [0, 0])


def test_synthetic_systems_check_their_settings():
    from hwpts.errors import ParameterError
    from hwpts.identification.synthetic import make_system

    for number, kwargs, match in [(6, {}, "number must be one of"), (1, {"n": -5}, "n must be an int >= 10"),
                                  (1, {"sigma": float("nan")}, "sigma must be a number >= 0"),
                                  (1, {"N": 3}, "unknown setting")]:
        with pytest.raises(ParameterError, match=match):
            make_system(number, **kwargs)


def test_held_out_fit_is_the_blocks_own_fit_or_against_the_whole_spread_where_the_output_rests():
    """A block's score in the model search: its own fit %; where the output rests over the block
    (its own fit % undefined) 100 (1 - RMSE / spread of the whole output), which survives a 1e160
    scale."""
    rng = np.random.default_rng(0)
    y = rng.standard_normal(500)
    yhat = y + 0.1 * rng.standard_normal(500)
    spread = output_spread(y)
    assert spread == pytest.approx(np.std(y))
    assert held_out_fit(y[:50], yhat[:50], spread) == fit_percent(y[:50], yhat[:50])
    rest = np.zeros(50)
    assert held_out_fit(rest, rest + 0.1 * spread, spread) == pytest.approx(90.0)
    with pytest.raises(DataError, match="constant measured output"):
        fit_percent(rest, rest + 0.1)
    assert held_out_fit(rest + 1e160, rest + 1e160 + 0.1 * spread * 1e160, spread * 1e160) == pytest.approx(90.0)
    assert output_spread(y * 1e160) == pytest.approx(spread * 1e160)
    assert np.isnan(held_out_fit(y, np.full_like(y, np.nan), spread))
    # at rest to rounding (a spread 1e-9 of the record's or less) as at rest: it scored -1e10 %
    nearly = rest.copy()
    nearly[5] = 1e-9 * spread
    assert held_out_fit(nearly, nearly + 0.1 * spread, spread) == pytest.approx(90.0)
    with pytest.raises(DataError, match="empty"):
        held_out_fit([], [], spread)
    # a simulation scores a block so when given the record's spread (the search's one path)
    from hwpts.identification.simulation import SimulationResult

    run = SimulationResult(np.concatenate([[0.0], rest + 0.1 * spread]), np.zeros(51, dtype=int), 1)
    assert run.score(np.zeros(51), spread) == pytest.approx(90.0)
    assert np.isnan(SimulationResult(np.zeros(51), np.zeros(51, dtype=int), 1, diverged=True).score(y[:51], spread))
    with pytest.raises(DataError, match="an output that varies"):
        held_out_fit(rest, rest, 0.0)
