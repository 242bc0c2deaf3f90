"""Settings of the estimator and the search are checked before any fit: one ParameterError naming
the setting, what it takes and what it got (never a misspelt method dropped in silence, a string
read as True, or a library's own message about one of its internals)."""

import numpy as np
import pytest

from hwpts.errors import DataError, ParameterError
from hwpts.identification import PWARX, PWARXSearch, fit_percent
from hwpts.identification.segmentation import make_segmenter


def two_modes(n=600, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, n)
    y = np.zeros(n)
    for k in range(1, n):
        y[k] = 0.5 * y[k - 1] + u[k - 1] + 0.2 if y[k - 1] >= 0 else -0.4 * y[k - 1] + 2 * u[k - 1] - 0.1
        y[k] += 0.01 * rng.standard_normal()
    return u[:, None], y


@pytest.mark.parametrize("setting, match", [
    (dict(constant="no"), "constant must be True or False, got 'no'"),
    (dict(polish="yes"), "polish must be True or False"),
    (dict(sparse_partition="no"), "sparse_partition must be True or False"),
    (dict(ridge="a"), "ridge must be a number >= 0, got 'a'"),
    (dict(ridge=-1.0), "ridge must be a number >= 0"),
    (dict(classifier_C=0), "classifier_C must be a number > 0, got 0"),
    (dict(classifier_C=float("nan")), "classifier_C must be a number > 0"),
    (dict(refinement_rounds=1.5), "refinement_rounds must be an int >= 0, got 1.5"),
    (dict(refinement_rounds=-1), "refinement_rounds must be an int >= 0"),
    (dict(random_state="a"), "random_state must be None, an int >= 0 or a numpy Generator or SeedSequence, got 'a'"),
    # found by a review (2026-11-26): these raised a TypeError or a library's message from inside
    (dict(segmentation="threshold", segmentation_params=[1, 2]), "segmentation_params must be a dict"),
    (dict(segmentation="alternating", partition_columns=[]), "partition_columns must be a column name or a non-empty list"),
    (dict(segmentation="alternating", partition_columns=5), "partition_columns must be"),
    (dict(segmentation="hyperplane", hyperplanes=5), "hyperplanes must be a list of hyperplanes"),
    (dict(segmentation="threshold", region_models=5), "region_models must be a list"),
    (dict(segmentation="threshold", region_models="affine"), "region_models must be a list"),
])
def test_estimator_settings_are_checked(setting, match):
    u, y = two_modes()
    with pytest.raises(ParameterError, match=match):
        PWARX(1, 1, 1, **setting).fit(u, y)


@pytest.mark.parametrize("names, match", [
    (["y"], "input name 'y' is the output's name"),
    (["a", "a"], "input name 'a' is two inputs' name"),
    (["a"], "input_names has 1 names for 2 input columns"),
])
def test_input_names_must_name_each_input_once(names, match):
    u, y = two_modes()
    u2 = np.column_stack([u[:, 0], u[::-1, 0]])
    with pytest.raises(ParameterError, match=match):
        PWARX(1, 1, 1).fit(u if names == ["y"] else u2, y, input_names=names, output_name="y")


@pytest.mark.parametrize("breaks", ["300", [0], [600], [5000], [2.5]])
def test_breaks_must_be_positions_inside_the_record(breaks):
    u, y = two_modes()
    with pytest.raises(ParameterError, match="breaks must be"):
        PWARX(1, 1, 1).fit(u, y, breaks=breaks)


def test_breaks_drop_the_rows_that_span_them():
    u, y = two_modes()
    whole = PWARX(1, 1, 1, segmentation="threshold", n_regions=2, random_state=0).fit(u, y)
    split = PWARX(1, 1, 1, segmentation="threshold", n_regions=2, random_state=0).fit(u, y, breaks=[300, 300])
    assert not np.allclose(whole.theta_, split.theta_)  # one row fewer, the same model nearly
    np.testing.assert_allclose(whole.theta_, split.theta_, atol=0.05)


@pytest.mark.parametrize("setting, match", [
    (dict(methods=["treshold"]), "methods has 'treshold'; valid are"),
    (dict(methods=[3]), "methods has 3"),
    (dict(methods=[]), "methods leaves nothing to try"),
    (dict(methods=5), "methods must be a list of segmentation names"),
    # every candidate failed (hyperplane) or made one model at every count, and the shared modes won
    (dict(methods=["hyperplane"]), "methods has 'hyperplane', whose regions are its own rule or given hyperplanes"),
    (dict(methods=["threshold", "zscore"]), "methods has 'zscore', whose regions .* expected methods that learn"),
    (dict(methods=["average"]), r"methods has 'average'.* fit PWARX\(segmentation='average'\) alone"),
    (dict(max_regions=0), "max_regions must be 'auto' or an int >= 1, got 0"),
    (dict(max_regions=2.5), "max_regions must be 'auto' or an int >= 1"),
    (dict(patience=0), "patience must be an int >= 1, got 0"),
    (dict(n_orders=1.5), "n_orders must be an int >= 1"),
    (dict(refit_margin=float("nan")), "refit_margin must be a number >= 0, got nan"),
    (dict(refit_margin=-1), "refit_margin must be a number >= 0"),
    (dict(tolerance=-0.1), "tolerance must be a number >= 0"),
    (dict(try_polish="no"), "try_polish must be True, False or 'auto', got 'no'"),
    (dict(try_polish=1), "try_polish must be True, False or 'auto'"),
    (dict(progress="yes"), "progress must be True or False"),
    (dict(cv="a"), "cv must be None, an int >= 2"),
    (dict(cv=1), "cv must be None, an int >= 2"),
    (dict(n_jobs=0), "n_jobs must be None or a non-zero int"),
])
def test_search_settings_are_checked(setting, match):
    u, y = two_modes()
    with pytest.raises(ParameterError, match=match):
        PWARXSearch(PWARX(1, 1, 1, random_state=0), **setting).fit(u, y)


@pytest.mark.parametrize("fit_args, match", [
    (dict(sample_time="0.1"), "sample_time must be a number of seconds >= 1e-12"),
    (dict(sample_time=1e-13), "sample_time must be a number of seconds >= 1e-12 .* got 1e-13"),
    (dict(units=5), "units must be a dict"),
    (dict(output_name=5), "output_name must be a non-empty string"),
])
def test_fit_arguments_are_checked_before_the_model_changes(fit_args, match):
    u, y = two_modes()
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(u, y, units={"y": "mm"})
    before = model.theta_.copy()
    with pytest.raises(ParameterError, match=match):
        model.fit(np.column_stack([u, u ** 2]), y, **fit_args)
    assert model.n_features_in_ == 1 and np.array_equal(model.theta_, before) and model.units_ == {"y": "mm"}
    with pytest.raises(ParameterError, match=match):
        PWARXSearch(PWARX(1, 1, 1, random_state=0)).fit(u, y, **fit_args)


def test_the_search_says_what_the_estimator_says_not_that_every_candidate_failed():
    """A bad estimator setting, a constant output or a grid naming no setting of the estimator
    was reported as 'every candidate model diverged in free run or failed' (a RuntimeError)."""
    u, y = two_modes()
    with pytest.raises(ParameterError, match="^ridge must be a number >= 0, got -1"):
        PWARXSearch(PWARX(1, 1, 1, ridge=-1)).fit(u, y)
    with pytest.raises(DataError, match="output 'y' is constant"):
        PWARXSearch(PWARX(1, 1, 1)).fit(u, np.ones(y.size))
    with pytest.raises(ParameterError, match=r"param_grid names \['foo'\], which the estimator does not have"):
        PWARXSearch(PWARX(1, 1, 1), param_grid={"foo": [1]}).fit(u, y)


def test_inputs_are_checked_without_an_output_and_a_short_record_is_all_initial_conditions():
    u, y = two_modes()
    model = PWARX(3, 2, 1, segmentation="threshold", random_state=0).fit(u, y)
    bad = u.copy()
    bad[50, 0] = np.nan
    with pytest.raises(DataError, match="inputs has a non-finite value .* at row 50"):
        model.simulate(bad, initial_output=y[:3])  # was a run 'diverged' at sample 50
    bad[50, 0] = 1e300
    with pytest.raises(DataError, match="inputs has the value 1e\\+300 at row 50"):
        model.simulate(bad, initial_output=y[:3])
    static = PWARX(0, 1, 0, segmentation="threshold", random_state=0).fit(u, np.abs(u[:, 0]))
    bad[50, 0] = np.nan
    with pytest.raises(DataError, match="non-finite"):
        static.predict(bad)  # was nan at row 50
    for n in (1, 2, 3):  # n < max_lag with the measured output: the initial conditions only (n = 2 raised
        np.testing.assert_array_equal(model.simulate(u[:n], y[:n]).output, y[:n])  # a broadcast error)


def test_pandas_records_read_by_position_are_refused_where_position_is_wrong():
    pd = pytest.importorskip("pandas")
    u, y = two_modes()
    index = pd.date_range("2026-01-01", periods=y.size, freq="s")
    X, Y = pd.DataFrame({"u": u[:, 0]}, index=index), pd.Series(y, index=index, name="y")
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(X, Y)
    with pytest.raises(DataError, match="X and y have different indexes"):
        PWARX(1, 1, 1).fit(X, Y.iloc[::-1])
    with pytest.raises(DataError, match="X and y have different indexes"):
        model.predict(X, Y.sample(frac=1.0, random_state=0))
    with pytest.raises(DataError, match="time index is not increasing"):
        PWARX(1, 1, 1).fit(X.iloc[::-1], Y.iloc[::-1])
    plain = pd.DataFrame({"u": u[:, 0], "y": y})  # a RangeIndex, then shuffled (df.sample)
    PWARX(1, 1, 1, segmentation="average", n_regions=1).fit(plain[["u"]], plain["y"])
    shuffled = plain.sample(frac=1.0, random_state=0)
    with pytest.raises(DataError, match=r"X's index is not increasing \(rows are read in order"):
        PWARX(1, 1, 1).fit(shuffled[["u"]], shuffled["y"])
    with pytest.raises(DataError, match="index is not increasing"):
        model.score(shuffled[["u"]], shuffled["y"])
    with pytest.raises(DataError, match="holds dates or durations"):
        PWARX(1, 1, 1).fit(pd.DataFrame({"u": index}), y)


def test_one_method_name_is_one_method():
    u, y = two_modes()
    search = PWARXSearch(PWARX(1, 1, 1, random_state=0), methods="threshold", shared_modes=False,
                         output_powers=None).fit(u, y)
    tried = {r["params"].get("segmentation") for r in search.cv_results_}
    assert tried <= {"average", "threshold"} and "threshold" in tried
    assert all(r["error"] is None for r in search.cv_results_)


def test_simulate_before_fit_and_short_initial_outputs():
    u, y = two_modes()
    with pytest.raises(Exception, match="not fitted"):
        PWARX().simulate(u, y)
    model = PWARX(2, 1, 1, segmentation="threshold", n_regions=2, random_state=0).fit(u, y)
    with pytest.raises(DataError, match="need 2 initial outputs, got 1"):
        model.simulate(u[:2], initial_output=[0.1])  # not broadcast into both lags
    np.testing.assert_array_equal(model.simulate(u[:2], initial_output=[0.1, 0.2]).output, [0.1, 0.2])
    np.testing.assert_array_equal(model.simulate(u[:2], initial_output=[[0.1, 0.2]]).output, [0.1, 0.2])


def test_what_would_be_ignored_is_refused():
    """Arguments that were read past without a word: a measured output beside initial_output (which
    one sets the start?), a matrix of initial outputs flattened, names beside an IODataset's own,
    text read as numbers (scikit-learn refuses it too)."""
    from hwpts.dataset import IODataset

    u, y = two_modes()
    model = PWARX(2, 1, 1, segmentation="threshold", n_regions=2, random_state=0).fit(u, y)
    with pytest.raises(ParameterError, match="from initial_output or from the measured output"):
        model.simulate(u, y, initial_output=y[:2])
    with pytest.raises(DataError, match=r"initial_output must be a vector of the first outputs, got shape \(2, 2\)"):
        model.simulate(u, initial_output=[[1.0, 2.0], [3.0, 4.0]])
    data = IODataset(np.arange(y.size, dtype=float), u.reshape(-1, 1), y, ("u",), "y")
    with pytest.raises(ParameterError, match="input_names and output_name are the IODataset's own"):
        PWARX(1, 1, 1).fit(data, input_names=["zz"])
    with pytest.raises(DataError, match="inputs holds text"):
        PWARX(1, 1, 1).fit(u.astype(str), y)
    with pytest.raises(DataError, match="inputs holds text"):  # an object array (a DataFrame's strings) alike
        PWARX(1, 1, 1).fit(u.astype(str).astype(object), y)
    with pytest.raises(DataError, match="initial_output holds text"):
        model.simulate(u, initial_output=["0.1", "0.2"])
    PWARX(1, 1, 1, segmentation="average", n_regions=1).fit(u.astype(object), y)  # numbers in objects: numbers


def test_settings_that_worked_before_their_checks_still_do():
    """A whole float for n_grid, no trimming (None), no regularisation (infinity) were refused by
    the first version of these checks."""
    from hwpts.identification.partition import PartitionLearner

    u, y = two_modes()
    PWARX(1, 1, 1, segmentation="threshold", segmentation_params={"n_grid": 50.0}).fit(u, y)
    X = np.column_stack([y[:-1], u[:-1, 0]])
    labels = (X[:, 0] >= 0).astype(int)
    for setting in ({"trim": None}, {"C": np.inf}, {"confidence_margin": np.inf}, {"separable_C": None}):
        learned, _, _ = PartitionLearner(random_state=0, **setting).learn(X, y[1:], labels, 2)
        assert np.mean(learned == labels) > 0.95, setting


def test_a_score_against_a_measured_nan_is_an_error():
    with pytest.raises(DataError, match="1 non-finite value"):
        fit_percent([1.0, np.nan, 3.0], [1.0, 2.0, 3.0])
    assert np.isnan(fit_percent([1.0, 2.0, 3.0], [1.0, np.nan, 3.0]))  # a diverged prediction


@pytest.mark.parametrize("shift", ["gap", "jitter"])
def test_a_dataset_with_a_gap_or_jitter_in_time_is_refused(shift):
    from hwpts.dataset import IODataset

    u, y = two_modes(1000)
    t = np.arange(1000) * 0.01
    if shift == "gap":
        t[500:] += 50.0  # two experiments joined: a row spanning the gap would mix them
    else:
        t = t + np.random.default_rng(1).uniform(-0.004, 0.004, 1000)
    data = IODataset(t, u, y, ["u"], "y")
    with pytest.raises(DataError, match="the dataset's time is not uniformly sampled"):
        PWARX(1, 1, 1).fit(data)
    with pytest.raises(DataError, match="not uniformly sampled"):
        PWARXSearch(PWARX(1, 1, 1), methods="threshold").fit(data)
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(u, y, breaks=[500] if shift == "gap" else None)
    with pytest.raises(DataError, match="not uniformly sampled"):
        model.simulate(data)


@pytest.mark.parametrize("method, params, match", [
    ("alternating", {"gamma": float("nan")}, "alternating: gamma must be a number >= 0, got nan"),
    ("alternating", {"n_restarts": 0}, "alternating: n_restarts must be an int >= 1 or 'auto', got 0"),
    ("alternating", {"max_iter": 0}, "alternating: max_iter must be an int >= 1"),
    ("alternating", {"anneal": (0,)}, "alternating: anneal must be a list of numbers > 0"),
    ("clustering", {"n_neighbors": 1}, "clustering: n_neighbors must be an int >= 2, got 1"),
    ("clustering", {"n_init": 0}, "clustering: n_init must be an int >= 1"),
    ("kmeans", {"n_init": 2.5}, "kmeans: n_init must be an int >= 1"),
    ("kmeans", {"include_output": "yes"}, "kmeans: include_output must be True or False"),
    ("threshold", {"n_grid": "x"}, "threshold: n_grid must be an int >= 2, got 'x'"),
    ("threshold", {"n_grid": 2.5}, "threshold: n_grid must be an int >= 2, got 2.5"),
    ("threshold", {"min_share": "x"}, r"threshold: min_share must be a number in \(0, 0.5\)"),
    ("threshold", {"column": 3}, "threshold: column must be a regressor column name"),
    ("threshold-alternating", {"n_grid": None}, "threshold-alternating: n_grid must be an int >= 2, got None"),
    ("zscore", {"threshold": "a"}, "zscore: threshold must be a finite number"),
    ("zscore", {"threshold": [0.0]}, "zscore: threshold must be a finite number"),
    ("hyperplane", {"hyperplanes": "1,0,0"}, "hyperplane: hyperplanes must be a list of 'a,b,c' texts"),
])
def test_segmenter_settings_are_checked(method, params, match):
    """Every method's settings are said in one line before any fit (numpy's or Python's own errors
    came out of the threshold's and zscore's, and a string of hyperplanes was read letter by letter)."""
    u, y = two_modes()
    with pytest.raises(ParameterError, match=match):
        PWARX(1, 1, 1, segmentation=method, segmentation_params=params, random_state=0).fit(u, y)
    segmenter = make_segmenter(method, **params)
    with pytest.raises(ParameterError, match=match):
        segmenter.check_params()


@pytest.mark.parametrize("estimator, grid, match", [
    (PWARX(1, 1, 1), {"n_regions": [2, 0]}, r"candidate \{'n_regions': 0\}: n_regions must be an int >= 1, got 0"),
    (PWARX(1, 1, 1), {"n_regions": [2, "x"]}, "n_regions must be an int >= 1, got 'x'"),
    (PWARX(1, 1, 1), {"output_order": [1, -2]}, "na \\(output order\\) must be an int >= 0, got -2"),
    (PWARX(1, 1, 1), {"ridge": [0, -1]}, "ridge must be a number >= 0, got -1"),
    (PWARX(1, 1, 1), {"segmentation": ["auto"]}, "segmentation 'auto' is a model search, not a model"),
    (PWARX(1, 1, 1), {"segmentation": ["threshold"], "segmentation_params": [{"n_grid": 1}]},
     "threshold: n_grid must be an int >= 2, got 1"),
    (PWARX(-1, 1, 1), None, "^PWARXSearch: na \\(output order\\) must be an int >= 0, got -1"),
    (PWARX(1, (1, 1), 1), None, "^PWARXSearch: nb \\(input order\\) has 2 entries but there are 1 inputs"),
])
def test_a_bad_value_in_the_grid_or_the_estimator_is_said_before_any_fit(estimator, grid, match):
    """A grid's bad value was fitted, failed, and left out of the choice without a word (an
    estimator's bad order surfaced as 'every candidate failed', a RuntimeError)."""
    u, y = two_modes()
    with pytest.raises(ParameterError, match=match):
        PWARXSearch(estimator, grid).fit(u, y)


def test_the_estimators_method_settings_are_the_candidates_to_check():
    """The base's own method is replaced by every candidate's: its settings are checked with the
    candidate's method, not with the method the base names (that refused hyperplanes a grid's
    'hyperplane' candidates use, and a threshold setting beside the default 'clustering')."""
    u, y = two_modes()
    search = PWARXSearch(PWARX(1, 1, 1, hyperplanes=["1,0@y(k-1)"]), {"segmentation": ["hyperplane"]}).fit(u, y)
    assert search.best_params_ == {"segmentation": "hyperplane"}
    search = PWARXSearch(PWARX(1, 1, 1, segmentation_params={"min_share": 0.2}, random_state=0),
                         {"segmentation": ["threshold", "threshold-alternating"]}).fit(u, y)
    assert search.best_params_["segmentation"] in ("threshold", "threshold-alternating")
    with pytest.raises(ParameterError, match="output_order must be an int >= 0 .* got None"):
        PWARXSearch(PWARX(1, 1, 1), {"output_order": [None, 1]}).fit(u, y)


def test_one_partition_column_name_is_one_column_and_an_empty_simulation_is_refused():
    u, y = two_modes()
    one = PWARX(1, 1, 1, segmentation="alternating", partition_columns="y(k-1)", random_state=0).fit(u, y)
    listed = PWARX(1, 1, 1, segmentation="alternating", partition_columns=["y(k-1)"], random_state=0).fit(u, y)
    np.testing.assert_array_equal(one.theta_, listed.theta_)
    with pytest.raises(DataError, match="at least one sample"):
        one.simulate(u[:0], y[:0])


def test_a_prediction_needs_only_its_initial_conditions_and_a_static_map_no_output():
    """Prediction applied the fit's length rule (7 samples for 2/2/1 where 3 predict one); a
    static map refused to predict without the output it does not use."""
    u, y = two_modes()
    model = PWARX(2, 2, 1, segmentation="threshold", random_state=0).fit(u, y)
    np.testing.assert_allclose(model.predict(u[:3], y[:3]), model.predict(u[:6], y[:6])[:3])
    with pytest.raises(DataError, match="more than the 2 initial samples, got 2"):
        model.predict(u[:2], y[:2])
    static = PWARX(0, 1, 0, segmentation="threshold", random_state=0).fit(u, np.abs(u[:, 0]) + 0.5 * u[:, 0])
    np.testing.assert_allclose(static.predict(u[:4]), np.abs(u[:4, 0]) + 0.5 * u[:4, 0], atol=0.05)
    assert static.predict_regions(u[:4]).shape == (4,)


def test_an_output_at_rest_over_a_held_out_block_is_scored_and_a_tiny_output_is_not_called_constant():
    """A block where the output rests (a rig idle) has no fit % of its own: the search refused the
    record ("the output is constant over held-out block 4 of 5"); each block is now scored against
    the whole output's spread (held_out_fit)."""
    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, 1000)
    u[600:800] = 0.0
    y = np.zeros(1000)
    for k in range(1, 1000):
        y[k] = 0.8 * y[k - 1] + (0.5 if y[k - 1] > 0 else 1.0) * u[k - 1]
    y[600:800] = 0.0  # idle: the fourth held-out block (samples 600-799) at rest
    search = PWARXSearch(PWARX(1, 1, 1, random_state=0)).fit(u[:, None], y)
    scored = [r for r in search.cv_results_ if r["mean_fit_percent"] is not None]
    assert scored and all(np.isfinite(r["split_fits_percent"][3]) for r in scored)
    assert search.best_estimator_.n_regions_ == 2  # the two gains of the system
    # a tiny output is scaled first (its squares are subnormal or zero): the fit of the same
    # signal at another scale, where it was "varies by 2e-200 only", and 89.995 for 89.986 % at 1e-160
    assert fit_percent([1e-200, 3e-200, 2e-200], [0.0, 0.0, 0.0]) == fit_percent([1.0, 3.0, 2.0], [0.0, 0.0, 0.0])
    wave = np.sin(np.arange(200) / 5)
    guess = wave + 0.1 * np.cos(np.arange(200) / 3)
    assert fit_percent(wave * 1e-160, guess * 1e-160) == pytest.approx(fit_percent(wave, guess), abs=1e-9)


def test_the_search_delegates_what_its_model_does():
    u, y = two_modes()
    search = PWARXSearch(PWARX(1, 1, 1, random_state=0), methods="threshold", output_powers=None).fit(u, y)
    model = search.best_estimator_
    np.testing.assert_array_equal(search.predict(u, y, horizon=3), model.predict(u, y, horizon=3))
    np.testing.assert_array_equal(search.predict_regions(u, y), model.predict_regions(u, y))
    assert search.n_features_in_ == 1


def test_frames_a_named_series_and_a_model_fitted_on_arrays():
    pd = pytest.importorskip("pandas")
    u, y = two_modes()
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(pd.Series(u[:, 0], name="valve"), y)
    assert model.input_names_ == ("valve",)
    named = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(pd.Series(u[:, 0], name="v"), y,
                                                                          input_names=["valve"])
    assert named.input_names_ == ("valve",)
    plain = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(u, y)
    with pytest.warns(UserWarning, match="fitted without names"):
        got = plain.predict(pd.DataFrame({"valve": u[:, 0]}), y)
    np.testing.assert_array_equal(got, plain.predict(u, y))


def test_seeds_numpy_takes_and_an_input_named_y():
    """RandomState and SeedSequence seeds are accepted as numpy's default_rng takes them; an input
    named "y" beside an unnamed output leaves the output "y_out" (it was refused as the output's name)."""
    u, y = two_modes()
    for seed in (np.random.RandomState(0), np.random.SeedSequence(0), np.int64(3)):
        PWARX(1, 1, 1, segmentation="threshold", random_state=seed).fit(u, y)
    with pytest.raises(ParameterError, match="random_state must be None, an int >= 0 or a numpy Generator"):
        PWARX(1, 1, 1, random_state=-1).fit(u, y)
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(u, y, input_names=["y"])
    assert model.output_name_ == "y_out" and model.structure_.feature_names == ["y_out(k-1)", "y(k-1)"]
    with pytest.raises(ParameterError, match="input name 'y' is the output's name"):
        PWARX(1, 1, 1).fit(u, y, input_names=["y"], output_name="y")


def test_a_single_precision_time_axis_is_uniform_and_its_gap_is_not():
    """A 10 kHz axis stored in float32 near 1000 s has steps of 6e-5 or 1.2e-4 s (its rounding):
    uniform at 1e-4 s; a gap in it is still refused."""
    from hwpts.dataset import IODataset

    n = 10_000
    u = np.random.default_rng(0).uniform(-1, 1, (n, 1))
    t = (1000.0 + np.arange(n) * 1e-4).astype(np.float32).astype(float)
    assert IODataset(t, u, np.cumsum(u[:, 0]), ["u"], "y").uniform_sample_time() == 1e-4
    t[5000:] += 0.5
    with pytest.raises(DataError, match="not uniformly sampled"):
        IODataset(t, u, np.cumsum(u[:, 0]), ["u"], "y").uniform_sample_time()


def test_one_stable_linear_mode_is_not_called_diverged_far_beyond_its_training_range():
    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, 1000)
    y = np.zeros(1000)
    for k in range(1, 1000):
        y[k] = 0.9 * y[k - 1] + 0.1 * u[k - 1]
    model = PWARX(1, 1, 1, n_regions=1, segmentation="average").fit(u[:, None], y)
    big = 100 * y  # the same system driven 100x harder: exact, and 100x the training range
    assert model.score(100 * u[:, None], big) > 99.99
    switched = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(*two_modes())
    assert np.isfinite(switched.divergence_band()[1])  # switching stable modes can still diverge


def test_a_time_indexed_frame_gives_its_sample_time_and_data_at_another_rate_are_refused():
    """A DataFrame indexed by time stamps kept no sample time, and a model of 100 Hz data scored
    data at 1 kHz without a word (an IODataset's time was checked, a DataFrame's was not)."""
    pd = pytest.importorskip("pandas")
    u, y = two_modes()
    index = pd.date_range("2024-01-01", periods=y.size, freq="10ms")
    frame, output = pd.DataFrame({"u": u[:, 0]}, index=index), pd.Series(y, index=index, name="y")
    model = PWARX(1, 1, 1, segmentation="threshold", random_state=0).fit(frame, output)
    assert model.sample_time_ == 0.01
    assert PWARXSearch(PWARX(1, 1, 1, random_state=0), methods="threshold").fit(frame, output).best_estimator_.sample_time_ == 0.01
    periods = pd.period_range("2024-01-01", periods=y.size, freq="s")
    assert PWARX(1, 1, 1, segmentation="threshold").fit(pd.DataFrame({"u": u[:, 0]}, index=periods), y).sample_time_ == 1.0
    with pytest.raises(DataError, match="time index is sampled every 1 s, the model every 0.01 s"):
        model.score(pd.DataFrame({"u": u[:, 0]}, index=periods), pd.Series(y, index=periods))
    steps = pd.timedelta_range(0, periods=y.size, freq="20ms")
    assert PWARX(1, 1, 1, segmentation="threshold").fit(pd.DataFrame({"u": u[:, 0]}, index=steps), y).sample_time_ == 0.02
    fast = pd.date_range("2024-01-01", periods=y.size, freq="1ms")
    with pytest.raises(DataError, match="time index is sampled every 0.001 s, the model every 0.01 s"):
        model.score(pd.DataFrame({"u": u[:, 0]}, index=fast), pd.Series(y, index=fast))
    with pytest.raises(ParameterError, match="sample_time 0.5 s differs from the DataFrame's time index"):
        PWARX(1, 1, 1).fit(frame, output, sample_time=0.5)
    # an index with a gap was fitted as one record, its lags across the gap (as an IODataset's
    # time it is refused): refused unless the fit's breaks say where the record restarts; then
    # the stretches give the sample time
    gap = index[:-1].append(pd.DatetimeIndex([index[-1] + pd.Timedelta("4s")]))
    with pytest.raises(DataError, match=r"not uniformly sampled \(step 0.01 s, but 4.01 s at row 599\).*breaks"):
        PWARX(1, 1, 1, segmentation="threshold").fit(pd.DataFrame({"u": u[:, 0]}, index=gap), y)
    gapped = PWARX(1, 1, 1, segmentation="threshold").fit(pd.DataFrame({"u": u[:, 0]}, index=gap), y, breaks=[599])
    assert gapped.sample_time_ == 0.01
    with pytest.raises(DataError, match=r"not uniformly sampled .*: resample it \(X.resample"):
        model.score(pd.DataFrame({"u": u[:, 0]}, index=gap), y)
    with pytest.raises(DataError, match="not uniformly sampled .*search each stretch on its own"):
        PWARXSearch(PWARX(1, 1, 1)).fit(pd.DataFrame({"u": u[:, 0]}, index=gap), y)
    twice = index[:300].append(index[299:-1])  # a repeated time stamp: two samples of one instant
    with pytest.raises(DataError, match="repeats a time stamp at row 300"):
        PWARX(1, 1, 1).fit(pd.DataFrame({"u": u[:, 0]}, index=twice), y)
    slower = index[:300].append(pd.date_range(index[299] + pd.Timedelta("1s"), periods=300, freq="20ms"))
    with pytest.raises(DataError, match="steps 0.01 s, but 0.02 s from row 300"):
        PWARX(1, 1, 1).fit(pd.DataFrame({"u": u[:, 0]}, index=slower), y, breaks=[300])
    with pytest.warns(UserWarning, match="X has no column names"):
        assert model.score(u, y) == model.score(frame, output)  # arrays carry no rate to check


def test_search_messages_name_the_orders_and_the_cv_and_a_failed_fit_leaves_no_old_results():
    """{"output_order": 2} raised 'int' object is not iterable; orders up to 200 on 300 samples
    said only that the samples were too few; cv=1000 did not name cv; a second fit that failed
    kept the first fit's best_estimator_ beside its own new attributes."""
    from sklearn.exceptions import NotFittedError

    u, y = two_modes()
    single = PWARXSearch(PWARX(random_state=0), orders={"output_order": 1, "input_order": [1], "input_delay": [1]},
                         methods="threshold", output_powers=None, try_polish=False).fit(u, y)
    assert single.best_params_["output_order"] == 1
    with pytest.raises(ParameterError, match=r"the largest lag, 200, is that of the orders \{'output_order': 200"):
        PWARXSearch(PWARX(random_state=0), orders={"output_order": [1, 200]}).fit(u[:300], y[:300])
    with pytest.raises(ParameterError, match=r"PWARXSearch: cv=1000: 300 samples cannot make 1000 blocks"):
        PWARXSearch(PWARX(1, 1, 1, random_state=0), cv=1000).fit(u[:300], y[:300])
    with pytest.raises(ParameterError, match="too few to choose a model"):
        single.fit(u[:5], y[:5])
    with pytest.raises(NotFittedError):
        single.predict(u, y)


def test_cv_takes_a_list_of_train_test_pairs_and_checks_them():
    """scikit-learn's searches take cv as (train, test) pairs; it was refused, printing every index."""
    u, y = two_modes()
    idx = np.arange(600)
    search = PWARXSearch(PWARX(1, 1, 1, random_state=0), cv=[(idx[:400], idx[400:]), (idx[200:], idx[:200])],
                         methods="threshold", output_powers=None, try_polish=False).fit(u, y)
    assert search.n_splits_ == 2 and len(search.cv_results_[0]["split_fits_percent"]) == 2
    with pytest.raises(ParameterError, match=r"cv=\[\(array\(\[ 0, 1, .*\.\.\.: every train and test part must be "
                                             r"a non-empty 1-D array of sample indices 0 .. 599"):
        PWARXSearch(PWARX(1, 1, 1), cv=[(idx[:400], idx[400:] + 100)]).fit(u, y)
    for cv in ([], (pair for pair in [(idx[:400], idx[400:])])):  # min() of an empty sequence; used up by one fit
        with pytest.raises(ParameterError, match="cv as \\(train, test\\) pairs must be a non-empty list of them"):
            PWARXSearch(PWARX(1, 1, 1), cv=cv).fit(u, y)
    with pytest.raises(ParameterError, match="a train part holds samples of its test block"):
        PWARXSearch(PWARX(1, 1, 1), cv=[(idx[:500], idx[400:])]).fit(u, y)


def test_arrays_for_a_model_fitted_on_named_columns_warn_as_scikit_learn():
    """Columns were taken by position without a word where the fit took them by name."""
    pd = pytest.importorskip("pandas")
    u, y = two_modes()
    model = PWARX(1, 1, 1, segmentation="threshold").fit(pd.DataFrame({"valve": u[:, 0]}), y)
    assert list(model.feature_names_in_) == ["valve"]
    with pytest.warns(UserWarning, match=r"X has no column names, but the model was fitted on a DataFrame with "
                                         r"columns \['valve'\]"):
        model.predict(u, y)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model.predict(pd.DataFrame({"valve": u[:, 0]}), y)  # by name: no warning
        model.fit(u, y).predict(u, y)  # refitted on arrays: none either
    assert not hasattr(model, "feature_names_in_")


def test_shared_modes_true_where_the_stage_is_not_run_is_refused():
    u, y = two_modes()
    for kwargs, said in ((dict(n_regions=3), "n_regions=3"), (dict(param_grid={"n_regions": [2]}), "a param_grid")):
        with pytest.raises(ParameterError, match=f"shared_modes=True is a stage .* with {said} it is not tried"):
            PWARXSearch(PWARX(1, 1, 1), shared_modes=True, **kwargs).fit(u, y)
