"""Export to python-control: each mode's response equals hwpts's free run restricted to that mode."""

import numpy as np
import pytest

from hwpts.identification import PWARX, RegionPartition
from hwpts.identification.analysis import mode_initial_state
from hwpts.identification.synthetic import make_system

control = pytest.importorskip("control")


@pytest.mark.parametrize("nk", [1, 0])
def test_each_mode_matches_python_control(nk):
    d = make_system(5, rng=0, n=3000)
    model = PWARX(2, 2, nk, n_regions=3, segmentation="alternating", random_state=0).fit(d.inputs, d.output)
    systems = model.to_control(dt=0.01)
    assert len(systems) == 3 and all(s.dt == 0.01 for s in systems)
    st = model.structure_
    rng = np.random.default_rng(1)
    n = 300
    u = rng.uniform(-1, 1, (n, 2))
    y0 = np.array([0.3, -0.2, 0.1])
    m = st.max_lag
    for i, sys in enumerate(systems):
        single = PWARX.from_parts(st, RegionPartition.single(st.n_features), model.theta_[i:i + 1])
        for forced in (True, False):
            uu = u if forced else np.zeros_like(u)
            ref = single.simulate(uu, initial_output=y0[:m]).output
            x0 = mode_initial_state(st, uu, np.concatenate([y0[:m], np.zeros(n - m)]), m)
            U = np.vstack([uu[m:].T, np.ones(n - m)])
            resp = control.forced_response(sys, T=np.arange(n - m) * 0.01, U=U, X0=x0)
            np.testing.assert_allclose(np.ravel(resp.outputs), ref[m:], rtol=0, atol=1e-9 * max(1.0, np.abs(ref).max()))


def test_to_control_rejects_a_bad_sample_time():
    from hwpts.errors import ParameterError

    d = make_system(5, rng=0, n=600)
    model = PWARX(2, 2, 1, n_regions=1, segmentation="average").fit(d.inputs, d.output)
    with pytest.raises(ParameterError, match="dt must be"):
        model.to_control(dt=-1.0)
    with pytest.raises(ParameterError, match="dt must be"):
        model.to_control(dt="a")
    (sys,) = model.to_control()
    assert sys.dt is True and list(sys.input_labels) == ["u1", "u2", "offset"]


def test_an_input_named_offset_keeps_its_own_channel():
    """python-control merges equal labels: an input named ``offset`` beside the constant channel
    made ``sys[:, "offset"]`` the constant; the constant is then ``offset_1``."""
    from hwpts.identification.analysis import state_space_export
    from hwpts.io.export import control_script

    d = make_system(5, rng=0, n=600)
    model = PWARX(2, 2, 1, n_regions=1, segmentation="average").fit(d.inputs, d.output, input_names=["offset", "p"])
    (sys,) = model.to_control()
    assert list(sys.input_labels) == ["offset", "p", "offset_1"] and sys.input_index["offset"] == 0
    assert "INPUTS = ['offset', 'p', 'offset_1']" in control_script(state_space_export(model), "test", "m")


def _two_mode_data(rng, n=400, sigma=0.1):
    """y(k) = a_i y(k-1) + b_i u1(k-1) + c_i + e(k), mode 1 where u1(k-1) >= 0 (a fixed partition)."""
    u = rng.uniform(-1, 1, (n, 2))
    y = np.zeros(n)
    e = sigma * rng.standard_normal(n)
    for k in range(1, n):
        if u[k - 1, 0] >= 0:
            y[k] = 0.5 * y[k - 1] + 1.0 * u[k - 1, 0] - 0.3 * u[k - 1, 1] + 0.2 + e[k]
        else:
            y[k] = -0.4 * y[k - 1] + 2.0 * u[k - 1, 0] + 0.5 * u[k - 1, 1] - 0.1 + e[k]
    return u, y


def test_parameter_std_matches_monte_carlo():
    # 200 noise realisations (inputs redrawn too): the spread of the estimates equals the mean
    # standard error the least squares reports, within 20 % for every parameter of every mode
    rng = np.random.default_rng(7)
    thetas, stds = [], []
    for _ in range(200):
        u, y = _two_mode_data(rng)
        model = PWARX(1, 1, 1, segmentation="hyperplane", hyperplanes=["1,0@u1(k-1)"]).fit(u, y)
        thetas.append(model.theta_)
        stds.append(model.parameter_std_)
    empirical = np.std(thetas, axis=0, ddof=1)
    reported = np.mean(stds, axis=0)
    assert empirical.shape == (2, 4)
    np.testing.assert_allclose(reported, empirical, rtol=0.2)


def test_parameter_std_survives_the_model_file(tmp_path):
    from hwpts.io.models import load_model, save_model

    u, y = _two_mode_data(np.random.default_rng(0))
    model = PWARX(1, 1, 1, segmentation="hyperplane", hyperplanes=["1,0@u1(k-1)"]).fit(u, y)
    assert np.all(np.isfinite(model.parameter_std_)) and np.all(model.parameter_std_ > 0)
    save_model(model, tmp_path / "m.json")
    back = load_model(tmp_path / "m.json")
    np.testing.assert_allclose(back.parameter_std_, model.parameter_std_, rtol=1e-12)
    np.testing.assert_allclose(back.parameter_cov_, model.parameter_cov_, rtol=1e-12)
    assert model.summary()["regions"][0]["theta_std"][0] > 0


def test_residuals_of_an_exact_model_are_called_exact():
    """A model that reproduces noise-free data leaves rounding errors (1e-16), which are correlated
    with its regressors: the analysis says the fit is exact instead of failing the whiteness test;
    on noisy data it does not."""
    from hwpts.identification.analysis import residual_analysis

    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, 800)
    y = np.zeros(800)
    for k in range(1, 800):
        y[k] = 0.5 * y[k - 1] + u[k - 1] + 0.2 if y[k - 1] >= 0 else -0.4 * y[k - 1] + 0.8 * u[k - 1] - 0.3
    model = PWARX(1, 1, 1, n_regions=2, segmentation="threshold").fit(u[:, None], y)
    exact = residual_analysis(model, u[:, None], y)
    assert exact.exact and exact.to_dict()["exact"] is True
    noisy = y + 0.05 * rng.standard_normal(800)
    assert not residual_analysis(model, u[:, None], noisy).exact


def test_a_confidence_whose_band_is_infinite_is_refused():
    """The command line refused 1 - 1e-16; the library returned a band of +-inf, 0 % outside."""
    from hwpts.errors import ParameterError
    from hwpts.identification.analysis import residual_analysis

    u, y = _two_mode_data(np.random.default_rng(0))
    model = PWARX(1, 1, 1, n_regions=1, segmentation="average").fit(u, y)
    with pytest.raises(ParameterError, match=r"confidence must lie in \(0.5, 0.999999999\], got 0.9999999999999999"):
        residual_analysis(model, u, y, confidence=0.9999999999999999)
    assert np.isfinite(residual_analysis(model, u, y, confidence=0.999999999).band)
