"""The simulation-error polish's compressed least squares (hwpts.identification.polish.compress)."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares

from hwpts.identification.polish import compress

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(n=st.integers(1, 60), q=st.integers(1, 12), seed=st.integers(0, 2**16),
       spread=st.floats(0.0, 6.0), zero_column=st.booleans())
def test_compression_keeps_sum_of_squares_gradient_and_gauss_newton_matrix(n, q, seed, spread, zero_column):
    """Columns scaled over ``spread`` decades, fewer rows than parameters, a column of zeros: the
    compressed (q + 1) x q problem has the full problem's r'r, J'r and J'J."""
    rng = np.random.default_rng(seed)
    jac = rng.standard_normal((n, q)) * 10.0 ** rng.uniform(-spread / 2, spread / 2, q)
    if zero_column:
        jac[:, rng.integers(q)] = 0.0
    r = rng.standard_normal(n)
    rc, jc = compress(r, jac)
    assert rc.shape == (q + 1,) and jc.shape == (q + 1, q)
    assert np.all(np.isfinite(rc)) and np.all(np.isfinite(jc))
    np.testing.assert_allclose(rc @ rc, r @ r, rtol=1e-9, atol=1e-12)
    scale = np.sqrt(np.sum(jac**2, axis=0))
    scale[scale == 0] = 1.0
    # compared column-scaled: the columns' magnitudes differ by up to `spread` decades
    np.testing.assert_allclose((jc.T @ rc) / scale, (jac.T @ r) / scale, rtol=1e-7,
                               atol=1e-7 * np.linalg.norm(r))
    np.testing.assert_allclose((jc.T @ jc) / np.outer(scale, scale), (jac.T @ jac) / np.outer(scale, scale),
                               atol=1e-9)


@pytest.mark.parametrize("method", ["trf", "lm"])
def test_solver_takes_the_same_path_on_the_compressed_problem(method):
    """A nonlinear least-squares problem (a sum of two decaying exponentials, 400 samples, 4
    parameters) solved on its residuals and on their compression: the same minimiser, the same
    number of evaluations (the trust-region steps depend only on r'r, J'r and J'J)."""
    t = np.linspace(0.0, 4.0, 400)
    rng = np.random.default_rng(1)
    data = 2.0 * np.exp(-1.3 * t) + 0.5 * np.exp(-0.2 * t) + 0.01 * rng.standard_normal(t.size)

    def residuals(p):
        return p[0] * np.exp(-p[1] * t) + p[2] * np.exp(-p[3] * t) - data

    def jacobian(p):
        return np.column_stack([np.exp(-p[1] * t), -p[0] * t * np.exp(-p[1] * t),
                                np.exp(-p[3] * t), -p[2] * t * np.exp(-p[3] * t)])

    p0 = np.array([1.0, 2.0, 1.0, 0.1])
    full = least_squares(residuals, p0, jac=jacobian, method=method, x_scale="jac", ftol=1e-10)
    small = least_squares(lambda p: compress(residuals(p), jacobian(p))[0], p0,
                          jac=lambda p: compress(residuals(p), jacobian(p))[1], method=method,
                          x_scale="jac", ftol=1e-10)
    assert full.success and small.success
    np.testing.assert_allclose(small.x, full.x, rtol=1e-6)
    assert small.nfev == full.nfev
    assert small.cost == pytest.approx(full.cost, rel=1e-9)


def test_gram_path_only_where_the_gauss_newton_matrix_keeps_its_digits():
    """The compression forms J'J only for a well-conditioned Jacobian (scaled condition number below
    about 1e5); otherwise (or with fewer rows than columns, or non-finite entries) it is not used."""
    from hwpts.identification.polish import gram_conditioned

    rng = np.random.default_rng(3)
    jac = rng.standard_normal((300, 6)) * np.array([1.0, 1e3, 1e-3, 1.0, 10.0, 1.0])  # scaling alone
    assert gram_conditioned(jac)
    near = jac.copy()
    near[:, 5] = near[:, 0] + 1e-7 * rng.standard_normal(300)  # two columns nearly equal: cond ~ 1e7
    assert not gram_conditioned(near)
    assert not gram_conditioned(jac[:4])
    bad = jac.copy()
    bad[0, 0] = np.nan
    assert not gram_conditioned(bad)
    # the QR path keeps the compression exact where the Gram path would lose the small direction
    r = rng.standard_normal(300)
    rc, jc = compress(r, near)
    np.testing.assert_allclose(jc.T @ rc, near.T @ r, rtol=1e-8, atol=1e-8 * np.abs(near.T @ r).max())
    np.testing.assert_allclose(rc @ rc, r @ r, rtol=1e-10)


@pytest.mark.parametrize("segmentation, kw", [("threshold", {}), ("alternating", {}),
                                              ("threshold", {"output_powers": (2, 3)})])
def test_the_polish_does_not_depend_on_where_the_signals_zeros_are(segmentation, kw):
    """The same data with the output 1000 higher and the input 50 higher (absolute or gauge
    pressure): the same polished model, its offset moved and nothing else. On raw signals the
    solvers' first trust region grew with the offsets and the polish landed elsewhere."""
    from hwpts.identification import PWARX

    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, (600, 1))
    y = np.zeros(600)
    for k in range(2, 600):
        y[k] = (0.9 if y[k - 1] > 0 else 0.5) * y[k - 1] - 0.1 * y[k - 2] + u[k - 1, 0] + 0.05 * rng.standard_normal()
    models = [PWARX(2, 1, 1, segmentation=segmentation, n_regions=2, polish=True, random_state=0, **kw)
              .fit(u + du, y + dy) for du, dy in ((0.0, 0.0), (50.0, 1000.0))]
    assert models[0].segmentation_info_["polish"]["accepted"]
    np.testing.assert_allclose(models[1].theta_[:, :-1], models[0].theta_[:, :-1], rtol=1e-5, atol=1e-7)
    assert models[1].score(u + 50.0, y + 1000.0) == pytest.approx(models[0].score(u, y), abs=1e-4)


def test_a_shifted_partition_holds_the_same_rows():
    """RegionPartition.shifted(m): row x - m of the copy is in the region of row x, whichever way
    the partition assigns rows (classifier scores, threshold cuts, polyhedra)."""
    from hwpts.identification.partition.polyhedra import RegionPartition, fit_linear_partition

    rng = np.random.default_rng(1)
    X = rng.standard_normal((300, 3))
    labels = (X[:, 0] + 0.5 * X[:, 1] > 0).astype(int) + (X[:, 2] > 1).astype(int)
    m = np.array([10.0, -3.0, 100.0])
    learned = fit_linear_partition(X, labels, 3)
    cut = RegionPartition([np.array([[1.0, 0, 0]]), np.array([[-1.0, 0, 0]])], [np.array([-0.2]), np.array([0.2])])
    cut.cuts = (0, np.array([0.2]))
    for partition in (learned, cut):
        shifted = partition.shifted(m)
        np.testing.assert_array_equal(shifted.predict(X - m), partition.predict(X))
        np.testing.assert_array_equal(shifted.violations(X - m).argmin(axis=1), partition.violations(X).argmin(axis=1))
