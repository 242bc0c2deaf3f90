"""The region classifier's Newton solver (partition.logistic) against scikit-learn's, its reference."""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from sklearn.linear_model import LogisticRegression

from hwpts.identification.partition import fit_linear_partition
from hwpts.identification.partition import polyhedra
from hwpts.identification.partition.logistic import newton_logistic


def _sklearn_scores(Z, y, C):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clf = LogisticRegression(C=C, solver="newton-cholesky", max_iter=200, tol=1e-10).fit(Z, y)
    return clf


def _centred(scores):
    """Scores up to the constant every class shares (the multinomial intercepts' free constant)."""
    return scores - scores.mean(axis=1, keepdims=True)


def _problem(seed, n, p, K, overlap):
    g = np.random.default_rng(seed)
    centres = g.normal(0.0, 2.0, (K, p))
    y = np.arange(n) % K
    Z = centres[y] + overlap * g.standard_normal((n, p))
    return (Z - Z.mean(0)) / Z.std(0), y


@pytest.mark.parametrize("K", [2, 3, 7])
@pytest.mark.parametrize("C", [1.0, 1e4])
def test_newton_reaches_scikit_learns_optimum(K, C):
    Z, y = _problem(K, 400, 3, K, 1.5)
    coef, icpt, n_iter = newton_logistic(Z, y, K, C, tol=1e-10)
    clf = _sklearn_scores(Z, y, C)
    assert coef.shape == clf.coef_.shape and icpt.shape == clf.intercept_.shape
    ours, theirs = Z @ coef.T + icpt, Z @ clf.coef_.T + clf.intercept_
    if K > 2:
        ours, theirs = _centred(ours), _centred(theirs)
    assert np.max(np.abs(ours - theirs)) <= 1e-5 * np.max(np.abs(theirs))
    assert 0 < n_iter <= clf.n_iter_[0] + 2  # Newton's rate: a wrong Hessian would take many more


@pytest.mark.parametrize("K", [2, 4])
def test_gradient_and_hessian_match_finite_differences_of_the_objective(K):
    from hwpts.identification.partition import logistic

    Z, y = _problem(10 + K, 80, 2, K, 1.0)
    n, p = Z.shape
    X1 = np.hstack([Z, np.ones((n, 1))])
    penalised = np.arange(p + 1) < p
    lam = 1e-2
    binary = K == 2
    Y = (y == 1).astype(float) if binary else y
    beta = np.random.default_rng(K).normal(size=(p + 1) if binary else (K, p + 1))
    f = lambda b: logistic._objective(b.reshape(beta.shape), X1, Y, lam, penalised, binary)[0]
    grad = lambda b: logistic._gradient_hessian(X1, Y, logistic._objective(b.reshape(beta.shape), X1, Y, lam, penalised, binary)[1],
                                                b.reshape(beta.shape), lam, penalised, binary)
    g, H = grad(beta.ravel())
    h = 1e-6
    eye = np.eye(beta.size)
    g_fd = np.array([(f(beta.ravel() + h * e) - f(beta.ravel() - h * e)) / (2 * h) for e in eye])
    H_fd = np.array([(grad(beta.ravel() + h * e)[0] - grad(beta.ravel() - h * e)[0]) / (2 * h) for e in eye])
    np.testing.assert_allclose(g, g_fd, rtol=1e-5, atol=1e-8)
    np.testing.assert_allclose(H, H_fd, rtol=1e-5, atol=1e-8)


def test_a_warm_start_at_the_optimum_takes_no_step():  # the solver itself
    Z, y = _problem(1, 300, 2, 4, 1.0)
    coef, icpt, _ = newton_logistic(Z, y, 4, 1e4, tol=1e-8)
    again = newton_logistic(Z, y, 4, 1e4, tol=1e-8, coef=coef, intercept=icpt)
    assert again[2] == 0
    np.testing.assert_array_equal(again[0], coef)


def test_the_iteration_cap_returns_the_iterate_as_scikit_learn_does():
    Z, y = _problem(2, 300, 2, 3, 0.2)  # separable: the weights grow for many iterations
    coef, _, n_iter = newton_logistic(Z, y, 3, 1e4, tol=1e-14, max_iter=2)
    assert n_iter == 2 and np.all(np.isfinite(coef))


def test_the_partition_falls_back_to_scikit_learn_where_newton_cannot_step(monkeypatch):
    Z, y = _problem(3, 300, 2, 3, 1.0)
    direct = fit_linear_partition(Z, y, 3)
    monkeypatch.setattr(polyhedra, "newton_logistic", lambda *a, **k: None)
    fallback = fit_linear_partition(Z, y, 3)
    np.testing.assert_array_equal(direct.predict(Z), fallback.predict(Z))


def _spy(monkeypatch):
    """Record the iteration counts of the Newton solver (None where it could not step) called
    through fit_linear_partition."""
    calls = []
    solver = polyhedra.newton_logistic

    def recording(*args, **kwargs):
        out = solver(*args, **kwargs)
        calls.append(None if out is None else out[2])
        return out

    monkeypatch.setattr(polyhedra, "newton_logistic", recording)
    return calls


def test_a_partition_warm_started_from_its_own_classifier_takes_no_newton_step(monkeypatch):
    X, y = _problem(6, 300, 3, 4, 1.0)
    X = 3.0 * X + 10.0  # raw coordinates: the start is converted to the standardised ones
    part = fit_linear_partition(X, y, 4)
    calls = _spy(monkeypatch)
    again = fit_linear_partition(X, y, 4, init=part)
    assert calls == [0]
    np.testing.assert_array_equal(again.predict(X), part.predict(X))


def test_absent_labels_keep_an_empty_region_with_the_newton_solver(monkeypatch):
    Z, y = _problem(4, 300, 2, 3, 1.0)
    y = np.where(y == 1, 3, y)  # regions 0, 2, 3 present, 1 absent
    calls = _spy(monkeypatch)
    part = fit_linear_partition(Z, y, 4)
    assert len(calls) == 1 and calls[0] is not None  # fitted by Newton, not the fallback
    assert set(np.unique(part.predict(Z))) <= {0, 2, 3}
    assert np.mean(part.predict(Z) == y) > 0.8


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), K=st.integers(2, 6), p=st.integers(1, 4),
       overlap=st.floats(0.3, 3.0))
def test_property_newton_and_scikit_learn_classify_alike(seed, K, p, overlap):
    Z, y = _problem(seed, 60 * K, p, K, overlap)
    fitted = newton_logistic(Z, y, K, 1e4, tol=1e-8)
    assert fitted is not None
    coef, icpt, _ = fitted
    clf = _sklearn_scores(Z, y, 1e4)
    ours, theirs = Z @ coef.T + icpt, Z @ clf.coef_.T + clf.intercept_
    if K == 2:
        ours, theirs = np.column_stack([0 * ours[:, 0], ours[:, 0]]), np.column_stack([0 * theirs[:, 0], theirs[:, 0]])
    # the same class wherever scikit-learn's top score leads by more than the solvers' tolerance
    top2 = np.sort(theirs, axis=1)[:, -2:]
    clear = top2[:, 1] - top2[:, 0] > 1e-3 * max(1.0, np.max(np.abs(theirs)))
    np.testing.assert_array_equal(ours.argmax(1)[clear], theirs.argmax(1)[clear])


def test_the_hessian_built_in_row_chunks_gives_the_same_fit(monkeypatch):
    from hwpts.identification.partition import logistic

    Z, y = _problem(5, 500, 3, 4, 1.0)
    whole = newton_logistic(Z, y, 4, 1e4)
    monkeypatch.setattr(logistic, "CHUNK_ROWS", 64)  # 8 chunks, the last one short
    chunked = newton_logistic(Z, y, 4, 1e4)
    assert whole[2] == chunked[2]
    np.testing.assert_allclose(chunked[0], whole[0], rtol=1e-9, atol=1e-9)


def test_a_constant_column_gets_no_weight_from_its_rounding():
    Z, y = _problem(7, 300, 2, 3, 1.0)
    X = np.column_stack([Z, np.full(300, 0.1)])  # its std is ~5e-16, not 0
    part = fit_linear_partition(X, y, 3)
    W, _ = part.scores
    assert np.max(np.abs(W[:, 2])) < 1e-6 * np.max(np.abs(W[:, :2]))
