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
