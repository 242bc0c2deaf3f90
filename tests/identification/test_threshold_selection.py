"""``threshold`` segmentation (SETAR/TARX) and the blocked cross-validation scheme of select_model."""

import numpy as np
import pytest

from hwpts.errors import ParameterError
from hwpts.identification import PWARX
from hwpts.identification.metrics import fit_percent
from hwpts.identification.segmentation.threshold import threshold_partition
from hwpts.identification.selection import expand_grid, select_model


def setar(n, seed, threshold=0.3, sigma=0.01):
    """y(k) = a_i y(k-1) + b_i u(k-1) + c_i with the mode set by y(k-1) <= threshold."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, n)
    y = np.zeros(n)
    for k in range(1, n):
        if y[k - 1] <= threshold:
            y[k] = 0.7 * y[k - 1] + 0.5 * u[k - 1] + 0.1
        else:
            y[k] = 0.3 * y[k - 1] + 0.2 * u[k - 1] + 0.25
        y[k] += sigma * rng.standard_normal()
    return u[:, None], y


def test_threshold_recovers_the_switching_level_and_is_deterministic():
    u, y = setar(3000, 0)
    m = PWARX(1, 1, 1, n_regions=2, segmentation="threshold", segmentation_params={"n_grid": 200}).fit(u, y)
    (t,) = m.segmentation_info_["thresholds"]
    assert abs(t - 0.3) < 0.02
    assert m.partition_.kind == "thresholds"
    np.testing.assert_allclose(m.theta_[0], [0.7, 0.5, 0.1], atol=0.02)
    np.testing.assert_allclose(m.theta_[1], [0.3, 0.2, 0.25], atol=0.02)
    again = PWARX(1, 1, 1, n_regions=2, segmentation="threshold", segmentation_params={"n_grid": 200},
                  random_state=5).fit(u, y)
    np.testing.assert_array_equal(m.theta_, again.theta_)
    uv, yv = setar(2000, 1)
    assert fit_percent(yv[1:], m.simulate(uv, yv).output[1:]) > 80  # process noise limits the free run


def test_threshold_three_regions_and_bad_parameters():
    u, y = setar(2000, 2)
    m = PWARX(2, 2, 1, n_regions=3, segmentation="threshold").fit(u, y)
    t = m.segmentation_info_["thresholds"]
    assert len(t) == 2 and t[0] < t[1] and m.n_regions_ == 3
    assert np.all(m.region_counts_ >= 0.05 * (len(y) - 2))
    with pytest.raises(ParameterError, match="1 to 3 regions"):
        PWARX(1, 1, 1, n_regions=4, segmentation="threshold").fit(u, y)
    with pytest.raises(ParameterError, match="unknown regressor column"):
        PWARX(1, 1, 1, segmentation="threshold", segmentation_params={"column": "y(k-3)"}).fit(u, y)


def test_threshold_partition_regions():
    p = threshold_partition(0, [0.0, 1.0], 2)
    x = np.array([[-1.0, 5], [0.0, 5], [0.5, -5], [1.0, 0], [2.0, 0]])
    np.testing.assert_array_equal(p.predict(x), [0, 0, 1, 1, 2])


def test_blocked_selection_covers_the_record_and_parallel_matches_sequential():
    u, y = setar(1500, 3)
    grid = expand_grid({"output_order": [1], "input_order": [1], "segmentation": ["average", "threshold"],
                        "n_regions": [2]})
    model, table = select_model(u, y, grid, n_folds=3, scheme="blocked")
    chosen = next(r for r in table if r.get("chosen"))
    assert chosen["params"]["segmentation"] == "threshold" and len(chosen["fits"]) == 3
    assert model.n_regions_ == 2
    _, table2 = select_model(u, y, grid, n_folds=3, scheme="blocked", n_jobs=2)
    assert [r["fits"] for r in table] == [r["fits"] for r in table2]
    with pytest.raises(ParameterError, match="unknown scheme"):
        select_model(u, y, grid, scheme="kfold")
    with pytest.raises(ParameterError, match="cannot make"):
        select_model(u, y, grid, n_folds=1, scheme="blocked")
