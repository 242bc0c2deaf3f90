"""Power terms of the standardised last output, ``((y(k-1) - c) / s)^p`` (``output_powers``):
a polynomial term in every mode, beyond the paper's affine modes (eq. 5)."""

import numpy as np
import pytest
from sklearn.base import clone

from hwpts.errors import DataError, ParameterError
from hwpts.identification import PWARX, PWARXSearch
from hwpts.identification.regressors import RegressorStructure


def duffing(n, seed, amplitude=1.0):
    """A discretised hardening spring (a Duffing oscillator, Silverbox's physics): affine in
    ``y(k-1), y(k-2), u(k-1)`` plus ``-0.2 y(k-1)^3``; stable for inputs up to about 1.4."""
    rng = np.random.default_rng(seed)
    u = amplitude * rng.uniform(-1, 1, n)
    y = np.zeros(n)
    for k in range(2, n):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] - 0.2 * y[k - 1] ** 3 + 0.5 * u[k - 1]
    return u[:, None], y


def test_columns_are_the_standardised_powers_of_the_last_output():
    st = RegressorStructure.create(2, 1, 1, 1, output_powers=[3, 2], power_center=1.0, power_scale=2.0)
    assert st.output_powers == (2, 3) and st.n_linear == 3 and st.n_features == 5 and st.n_parameters == 6
    assert st.feature_names[3:] == ["((y(k-1)-c)/s)^2", "((y(k-1)-c)/s)^3"]
    y = np.arange(10.0) ** 1.5
    X, t = st.build(np.arange(10.0), y)
    z = (y[1:-1] - 1.0) / 2.0  # y(k-1) for k = 2..9
    np.testing.assert_allclose(X[:, 3], z**2)
    np.testing.assert_allclose(X[:, 4], z**3)
    np.testing.assert_array_equal(st.powers, [1, 1, 1, 2, 3])
    assert "output powers [2, 3]" in st.describe_orders()
    back = RegressorStructure.from_dict(st.to_dict())
    assert back == st
    plain = RegressorStructure.create(2, 1, 1, 1)
    assert "output_powers" not in plain.to_dict()  # an affine model's file is as before
    assert RegressorStructure.from_dict(plain.to_dict()) == plain


@pytest.mark.parametrize("bad, match", [
    ([1], "distinct ints in 2..9"), ([2, 2], "distinct ints in 2..9"), ([10], "distinct ints in 2..9"),
    ([2.0], "distinct ints in 2..9"), ([True], "distinct ints in 2..9"), ("3", "distinct ints in 2..9"),
    (2.5, "list of ints"),
])
def test_bad_powers_are_refused(bad, match):
    with pytest.raises(ParameterError, match=match):
        RegressorStructure.create(1, 1, 1, 1, output_powers=bad)


def test_powers_need_an_output_lag_and_a_positive_scale():
    with pytest.raises(ParameterError, match=r"need y\(k-1\) in the regressor: na .* must be >= 1"):
        RegressorStructure.create(0, 2, 1, 1, output_powers=[2])
    with pytest.raises(ParameterError, match="power_scale"):
        RegressorStructure.create(1, 1, 1, 1, output_powers=[2], power_scale=0.0)


def test_compiled_simulation_agrees_with_the_python_reference():
    """The compiled free run, one-step and k-step predictions with power terms against a plain
    Python loop (:func:`simulate_true_pwarx`) and the free run restarted at each time."""
    from hwpts.identification.simulation import simulate_pwarx
    from hwpts.identification.synthetic import simulate_true_pwarx

    u, y = duffing(400, 0)
    model = PWARX(2, 1, 1, n_regions=2, segmentation="threshold", output_powers=(2, 3)).fit(u, y)
    st, part, theta = model.structure_, model.partition_, model.theta_
    free = model.simulate(u, y)
    ref, modes = simulate_true_pwarx(st, part, theta, u, np.zeros(len(y)), y[:2])
    np.testing.assert_allclose(free.output, ref, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(free.regions[2:], modes[2:])
    X, _ = st.build(u, y)
    np.testing.assert_allclose(model.predict(u, y)[2:], np.einsum("ij,ij->i", X, theta[part.predict(X), :-1])
                               + theta[part.predict(X), -1])
    q = model.predict(u, y, horizon=4)
    for t in (2, 3, 50, 399):
        s = max(t - 3, 2)
        run = simulate_pwarx(st, part, theta, u[s - 2:t + 1], y[s - 2:t + 1])
        assert abs(run.output[-1] - q[t]) < 1e-12


def test_free_run_sensitivity_includes_the_power_terms():
    """The polish's Jacobian with power terms (the chain through ``p z^(p-1) / s``) against central
    differences of the compiled simulator, regions held."""
    from hwpts.identification.simulation import free_run_sensitivity, simulate_pwarx

    u, y = duffing(500, 1)
    model = PWARX(2, 2, 1, n_regions=2, segmentation="threshold", output_powers=(2, 3)).fit(u, y)
    st, theta = model.structure_, model.theta_.copy()
    theta[:, :2] *= 0.97  # off the exact parameters: every term of the chain is active
    sim = simulate_pwarx(st, model.partition_, theta, u, y)
    J = free_run_sensitivity(st, theta, u, sim)
    eps = 1e-7
    for j in range(theta.size):
        up, down = theta.ravel().copy(), theta.ravel().copy()
        up[j] += eps
        down[j] -= eps
        a = simulate_pwarx(st, model.partition_, up.reshape(theta.shape), u, y)
        b = simulate_pwarx(st, model.partition_, down.reshape(theta.shape), u, y)
        same = (a.regions == sim.regions) & (b.regions == sim.regions)
        numeric = (a.output - b.output) / (2 * eps)
        assert np.allclose(J[same, j], numeric[same], rtol=1e-4, atol=1e-6 * max(1.0, np.abs(numeric).max()))


def test_a_cubic_spring_is_identified_and_extrapolated():
    """Noise-free Duffing data: with the square and the cube the model is exact (the cube of the
    *centred* output alone is not ``y^3``: ``(y - c)^3`` holds ``-3 c y^2``), and it stays exact on inputs 40 %
    larger than the training ones, where affine pieces fitted on the same data continue linearly."""
    u, y = duffing(3000, 2)
    u_big, y_big = duffing(3000, 3, amplitude=1.4)
    assert np.abs(y_big).max() > 1.2 * np.abs(y).max()  # the validation leaves the training range
    cubic = PWARX(2, 1, 1, n_regions=1, segmentation="average", output_powers=(2, 3)).fit(u, y)
    assert cubic.score(u, y) > 99.999
    assert cubic.score(u_big, y_big) > 99.99
    pieces = PWARX(2, 1, 1, n_regions=4, segmentation="threshold", random_state=0).fit(u, y)
    assert pieces.score(u_big, y_big) < cubic.score(u_big, y_big) - 1.0


def test_model_file_round_trip_and_affine_only_exports(tmp_path):
    from hwpts.control.model import ModelBank
    from hwpts.identification.analysis import state_space_export
    from hwpts.io.models import load_model, model_to_dict, save_model

    u, y = duffing(600, 4)
    model = PWARX(2, 1, 1, n_regions=2, segmentation="threshold", output_powers=(2, 3)).fit(u, y)
    path = tmp_path / "m.json"
    save_model(model, path)
    back = load_model(path)
    assert back.structure_ == model.structure_ and back.output_powers == (2, 3)
    np.testing.assert_array_equal(back.simulate(u, y).output, model.simulate(u, y).output)
    assert model.summary()["output_powers"] == [2, 3]
    assert clone(model).get_params()["output_powers"] == (2, 3)
    with pytest.raises(ParameterError, match="the state-space export needs affine modes.*output power terms"):
        state_space_export(back)
    with pytest.raises(ParameterError, match="to_control needs affine modes"):
        back.to_control()
    doc = model_to_dict(model)
    doc["structure"]["input_names"] = ["valve", "pump"]
    with pytest.raises(DataError, match="output power terms .* controllers are designed from affine modes"):
        ModelBank(doc)


def test_a_model_file_with_bad_power_fields_is_refused(tmp_path):
    import json

    from hwpts.io.models import checksum, load_model, model_to_dict

    u, y = duffing(600, 5)
    doc = model_to_dict(PWARX(2, 1, 1, n_regions=1, segmentation="average", output_powers=(3,)).fit(u, y))
    for field, value, match in (("output_powers", ["3"], "output_powers must be a list of ints"),
                                ("power_scale", None, "power_scale must be a number"),
                                ("power_scale", -1.0, "power_scale finite and > 0")):
        bad = json.loads(json.dumps(doc))
        bad["structure"][field] = value
        bad["checksum"]["value"] = checksum(bad)
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(bad))
        with pytest.raises(DataError, match=match):
            load_model(path)


def test_the_search_adds_the_powers_where_the_data_ask_for_them():
    """The adaptive search's powers stage (module doc, step 4): on a noisy hardening spring the
    cube is chosen; on a piecewise affine system (a threshold on the input) it is not; with
    ``output_powers=None`` it is not tried; a bad value is named."""
    u, y = duffing(2000, 6)
    y = y + 0.01 * np.random.default_rng(6).standard_normal(y.size)
    search = PWARXSearch(PWARX(2, 1, 1, random_state=0)).fit(u, y)
    assert search.best_estimator_.structure_.output_powers == (2, 3)
    assert any(r["stage"] == "powers" for r in search.cv_results_)
    off = PWARXSearch(PWARX(2, 1, 1, random_state=0), output_powers=None).fit(u, y)
    assert not any(r["stage"] == "powers" for r in off.cv_results_)
    assert off.best_estimator_.structure_.output_powers == ()
    assert search.best_score_ > off.best_score_ + 1  # 98.3 against 96.5 % held out

    rng = np.random.default_rng(7)
    v = rng.uniform(-1, 1, 2000)
    w = np.zeros(2000)
    for k in range(1, 2000):
        w[k] = (0.5 * w[k - 1] + v[k - 1] + 0.2) if v[k - 1] >= 0 else (-0.4 * w[k - 1] + 2 * v[k - 1] - 0.1)
    w += 0.02 * rng.standard_normal(2000)
    pwa = PWARXSearch(PWARX(1, 1, 1, random_state=0)).fit(v[:, None], w)
    assert any(r["stage"] == "powers" for r in pwa.cv_results_)
    assert pwa.best_estimator_.structure_.output_powers == () and pwa.best_estimator_.n_regions_ == 2
    for bad in ("yes", [1], [2, 2]):
        with pytest.raises(ParameterError, match="PWARXSearch: output_powers"):
            PWARXSearch(PWARX(1, 1, 1), output_powers=bad).fit(v[:, None], w)


def test_the_search_takes_powers_in_any_form_the_model_takes():
    """An int, an array or a grid of powers: the search counts their parameters as the model does
    (a review found ``len(3)`` and an array's truth value raising here), and an estimator with its
    own powers is searched only over orders with an output lag."""
    u, y = duffing(800, 8)
    for powers in (3, np.array([2, 3])):
        search = PWARXSearch(PWARX(2, 1, 1, random_state=0, output_powers=powers), max_regions=2).fit(u, y)
        assert search.best_estimator_.structure_.output_powers == tuple(np.atleast_1d(powers))
        assert not any(r["stage"] == "powers" for r in search.cv_results_)
    grid = PWARXSearch(PWARX(2, 1, 1), param_grid={"output_powers": [(), 3, (2, 3)], "n_regions": [1],
                                                    "segmentation": ["average"]}, try_polish=False).fit(u, y)
    assert grid.best_params_["output_powers"] == (2, 3)
    orders = PWARXSearch(PWARX(random_state=0, output_powers=(2, 3)), max_regions=1,
                         orders={"output_order": [0, 2], "input_order": [1], "input_delay": [1]}).fit(u, y)
    assert all(r["params"]["output_order"] == 2 for r in orders.cv_results_)
    with pytest.raises(ParameterError, match="need an output order >= 1"):
        PWARXSearch(PWARX(output_powers=(2,)), orders={"output_order": [0], "input_order": [1],
                                                        "input_delay": [1]}).fit(u, y)


from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

PROPERTY = settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(na=st.integers(1, 3), nb=st.integers(0, 2), powers=st.sets(st.integers(2, 4), min_size=1, max_size=3),
       seed=st.integers(0, 2**16))
def test_property_compiled_free_run_matches_the_reference_loop(na, nb, powers, seed):
    """Any orders and powers: the compiled free run (and the sensitivity kernel's rows) against the
    plain Python loop of :func:`simulate_true_pwarx`, for a stable random model."""
    from hwpts.identification.partition import RegionPartition
    from hwpts.identification.simulation import simulate_pwarx
    from hwpts.identification.synthetic import simulate_true_pwarx

    rng = np.random.default_rng(seed)
    st_ = RegressorStructure.create(na, nb, 1, 1, output_powers=powers, power_center=rng.normal(),
                                    power_scale=rng.uniform(0.5, 2.0))
    theta = np.zeros((1, st_.n_features + 1))
    theta[0, :na] = rng.uniform(-0.4, 0.4, na) / na
    theta[0, na:st_.n_linear] = rng.normal(size=nb)
    theta[0, st_.n_linear:-1] = rng.uniform(-0.01, 0.01, len(powers))
    theta[0, -1] = rng.normal()
    u = rng.uniform(-1, 1, (200, 1))
    y0 = rng.normal(size=st_.max_lag)
    part = RegionPartition.single(st_.n_features)
    sim = simulate_pwarx(st_, part, theta, u, y0, 0.0, 1e6)
    with np.errstate(over="ignore", invalid="ignore"):  # the reference runs on past a divergence
        ref, _ = simulate_true_pwarx(st_, part, theta, u, np.zeros(200), y0)
    if sim.diverged:  # (about 4 % of these draws) the reference leaves the band at the same sample
        k = sim.diverged_at
        assert not abs(ref[k]) <= 1e6
        np.testing.assert_allclose(sim.output[:k], ref[:k], rtol=1e-9, atol=1e-9)
    else:
        np.testing.assert_allclose(sim.output, ref, rtol=1e-9, atol=1e-9)


@PROPERTY
@given(scale=st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6]), shift=st.sampled_from([0.0, -50.0, 1e4]),
       seed=st.integers(0, 100))
def test_property_power_terms_do_not_depend_on_the_data_units(scale, shift, seed):
    """The terms are of the standardised output, so a model of ``a y + b`` predicts ``a yhat + b``:
    its fit on the same data is the same whatever the units (a cube of raw outputs offset by 1e4
    would be 1e12, collinear with the square and the output). The offset is ``shift`` times the
    output's scale: at 1e5 and a scale of 1e-6 the lagged outputs themselves are collinear."""
    u, y = duffing(600, seed)
    offset = shift * scale
    ref = PWARX(2, 1, 1, n_regions=1, segmentation="average", output_powers=(2, 3)).fit(u, y)
    moved = PWARX(2, 1, 1, n_regions=1, segmentation="average", output_powers=(2, 3)).fit(u, scale * y + offset)
    one = ref.predict(u, y)
    np.testing.assert_allclose(moved.predict(u, scale * y + offset), scale * one + offset,
                               rtol=1e-7, atol=1e-7 * scale * np.std(y))


@pytest.mark.parametrize("powered, chosen", [(90.3, ()), (91.0, (2, 3))])
def test_the_powers_must_beat_the_affine_pieces(monkeypatch, powered, chosen):
    """Made-up block fits: 2 threshold regions score 90 % on every block; the ARX model with the
    powers ties them (90.3 %, within the tolerance) or beats them (91 %). A tie keeps the affine
    pieces although the powered model has fewer regions and parameters (on a draining tank the
    cubic tied the pieces on the blocks and extrapolated 2.8 points worse); a gain takes the powers."""
    from hwpts.identification.selection import search as S

    def scored(estimator, params, u, y, splits, prune_below=-np.inf, names=None, output_name=None, leader=None,
               one_step=False, best_row=None):
        if params.get("output_powers"):
            free = powered if params["n_regions"] == 1 else powered - 5.0
        else:
            free = {1: 60.0, 2: 90.0}.get(params["n_regions"], 85.0)
        k = len(splits)
        return {"params": params, "split_fits_percent": [free] * k, "mean_fit_percent": free, "diverged": False,
                "pruned": False, "error": None, "n_regions_fitted": params["n_regions"], "fit_time_s": 0.0,
                "mean_one_step_fit_percent": 99.0, "split_one_step_fits_percent": [99.0] * k}

    monkeypatch.setattr(S, "_evaluate", scored)
    u, y = duffing(600, 9)
    # the refit on all data is real, its block fits are not the made-up ones: no refit check
    search = PWARXSearch(PWARX(2, 1, 1, random_state=0), methods=("threshold",), try_polish=False,
                         refit_margin=1000.0).fit(u, y)
    assert search.best_params_.get("output_powers", ()) == chosen
    assert search.best_params_["n_regions"] == (1 if chosen else 2)


def test_a_one_step_prediction_that_overflows_is_an_error_not_inf():
    """Data 1e60 times the training range: the cubic term's prediction passed 1e168 (squares
    overflow) and `hwpts residuals` called the inf residuals white with exit 0."""
    u, y = duffing(800, 0)
    model = PWARX(1, 1, 1, n_regions=1, segmentation="average", output_powers=(2, 3)).fit(u, y)
    with pytest.raises(DataError, match="one-step prediction overflows .* holds powers"):
        model.predict(u, y * 1e60)
    assert np.all(np.isfinite(model.predict(u, y)))
