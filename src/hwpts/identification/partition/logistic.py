"""Multinomial logistic regression by Newton's method with the Hessian built in one product.

The region classifiers of a learned partition are L2-penalised multinomial logistic regressions
(:func:`~hwpts.identification.partition.polyhedra.fit_linear_partition`), fitted hundreds of
times in a model search (every hard-EM step of ``switched``, every boundary refinement of the
partition learner), with few features and up to a few dozen classes. scikit-learn's
Newton-Cholesky solver reaches the same optimum but assembles the multinomial Hessian one pair
of classes at a time (``K (K + 1) / 2`` Python-level products per iteration): on 1,500 rows it
took 55 ms a fit at 14 classes and 108 ms at 20 where this solver takes 19 and 28 ms
(``python -m benchmarks classifier``). Here the Hessian is one
matrix product over all classes; scikit-learn stays the reference (the tests compare the two)
and the fallback where a Newton step cannot be taken (a Cholesky failure, no descent).

The problem is scikit-learn's ``LogisticRegression(C=C)``: minimise over the scores
``s_k(z) = w_k' z + b_k`` (``z`` the rows, standardised by the caller)::

    (1 / n) sum_i [log sum_k exp s_k(z_i) - s_{y_i}(z_i)] + 1 / (2 C n) sum_k |w_k|^2

with the intercepts unpenalised; two classes are one score (``s_1 - s_0``), as scikit-learn's
binary case. The multinomial objective does not change when a constant is added to every
intercept, so the first class's intercept is held at its start (probabilities, predictions and
the polyhedra depend on score differences only).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import LinAlgError, cho_factor, cho_solve

ARMIJO = 1e-4  # sufficient decrease of the backtracking line search
BACKTRACKS = 30  # step halvings before the line search gives up
CHUNK_ROWS = 32768  # rows of the Hessian's products at a time


def _objective(beta, X1, Y, lam, penalised, binary):
    """(loss, probabilities) at the coefficients ``beta`` ((q,) binary, (K, q) multinomial); ``Y``
    the targets: 0/1 (binary) or each row's class index."""
    if binary:
        eta = X1 @ beta
        # log(1 + e^eta) - y eta, stable for either sign of eta
        loss = np.mean(np.logaddexp(0.0, eta) - Y * eta)
        prob = 0.5 * (1.0 + np.tanh(0.5 * eta))
        return loss + 0.5 * lam * float(np.sum(beta[penalised] ** 2)), prob
    eta = X1 @ beta.T
    top = eta.max(axis=1, keepdims=True)
    expd = np.exp(eta - top)
    total = expd.sum(axis=1, keepdims=True)
    lse = np.log(total)[:, 0] + top[:, 0]
    loss = np.mean(lse - eta[np.arange(eta.shape[0]), Y])
    return loss + 0.5 * lam * float(np.sum(beta[:, penalised] ** 2)), expd / total


def _gradient_hessian(X1, Y, prob, beta, lam, penalised, binary):
    n, q = X1.shape
    if binary:
        g = X1.T @ (prob - Y) / n
        g[penalised] += lam * beta[penalised]
        H = (X1 * (prob * (1.0 - prob))[:, None]).T @ X1 / n
        H[penalised, penalised] += lam
        return g, H
    K = prob.shape[1]
    residual = prob.copy()
    residual[np.arange(n), Y] -= 1.0  # probabilities minus the one-hot targets
    g = (residual.T @ X1) / n
    g[:, penalised] += lam * beta[:, penalised]
    # H[(k, a), (l, b)] = mean_i (delta_kl p_ik - p_ik p_il) x_ia x_ib + lam delta_kl delta_ab [a penalised],
    # with A[i, (k, a)] = p_ik x_ia built CHUNK_ROWS rows at a time (its memory bounded on large data)
    H = np.zeros((K * q, K * q))
    blocks = np.zeros((K * q, q))  # row block k: sum_i p_ik x_i x_i'
    for lo in range(0, n, CHUNK_ROWS):
        P, X = prob[lo:lo + CHUNK_ROWS], X1[lo:lo + CHUNK_ROWS]
        A = (P[:, :, None] * X[:, None, :]).reshape(X.shape[0], K * q)
        H -= A.T @ A
        blocks += A.T @ X
    H /= n
    blocks /= n
    for k in range(K):
        H[k * q:(k + 1) * q, k * q:(k + 1) * q] += blocks[k * q:(k + 1) * q]
    diag = np.tile(np.where(penalised, lam, 0.0), K)
    H[np.diag_indices_from(H)] += diag
    return g.reshape(-1), H


def newton_logistic(Z: np.ndarray, y: np.ndarray, n_classes: int, C: float, tol: float = 1e-8,
                    max_iter: int = 100, coef=None, intercept=None):
    """Fit the penalised logistic regression above to rows ``Z`` (already standardised) and class
    indices ``y`` from 0 to ``n_classes - 1`` (every class present).

    ``coef``, ``intercept``: a start in scikit-learn's shapes (``(1, p)`` and ``(1,)`` for two
    classes, ``(K, p)`` and ``(K,)`` otherwise). Returns ``(coef, intercept, n_iter)`` in those
    shapes (where ``max |gradient| <= tol`` and half the squared Newton decrement ``<= tol``, or
    the iterate after ``max_iter`` steps, as scikit-learn),
    or None where a Newton step cannot be taken (the Hessian not positive definite to Cholesky, no
    descent direction or no decrease along it): the caller falls back to scikit-learn.
    """
    Z = np.asarray(Z, dtype=float)
    n, p = Z.shape
    K = int(n_classes)
    binary = K == 2
    X1 = np.hstack([Z, np.ones((n, 1))])
    q = p + 1
    penalised = np.arange(q) < p
    lam = 1.0 / (float(C) * n)
    if binary:
        Y = (y == 1).astype(float)
        beta = np.zeros(q)
        if coef is not None:
            beta[:p], beta[p] = np.asarray(coef, float).reshape(-1), float(np.asarray(intercept).reshape(-1)[0])
    else:
        Y = np.asarray(y, dtype=np.int64)
        beta = np.zeros((K, q))
        if coef is not None:
            beta[:, :p], beta[:, p] = np.asarray(coef, float), np.asarray(intercept, float)
    free = np.ones(beta.size, dtype=bool)
    if not binary:
        free[p] = False  # the first class's intercept: the objective's free constant
    f, prob = _objective(beta, X1, Y, lam, penalised, binary)
    for it in range(1, int(max_iter) + 1):
        g, H = _gradient_hessian(X1, Y, prob, beta, lam, penalised, binary)
        try:
            step = -cho_solve(cho_factor(H[np.ix_(free, free)], check_finite=False), g[free], check_finite=False)
        except (LinAlgError, ValueError):
            return None
        slope = float(g[free] @ step)
        # scikit-learn's two criteria: max |gradient| <= tol and half the squared Newton
        # decrement (-slope = step' H step) <= tol; the second matters where C is large (the
        # Hessian nearly singular), the first alone stopped an iteration early at C = 1e8
        if np.max(np.abs(g[free])) <= tol and -0.5 * slope <= tol:
            return _shaped(beta, p, binary) + (it - 1,)
        if not np.isfinite(slope) or slope >= 0.0:
            return None
        full = np.zeros(beta.size)
        full[free] = step
        full = full.reshape(beta.shape)
        t = 1.0
        for _ in range(BACKTRACKS):
            trial = beta + t * full
            f_trial, prob_trial = _objective(trial, X1, Y, lam, penalised, binary)
            if f_trial <= f + ARMIJO * t * slope:
                break
            t *= 0.5
        else:
            # no decrease representable in floating point: converged as far as it can be
            if abs(slope) <= 1e-14 * max(1.0, abs(f)):
                return _shaped(beta, p, binary) + (it,)
            return None
        beta, f, prob = trial, f_trial, prob_trial
    return _shaped(beta, p, binary) + (int(max_iter),)  # the cap reached: the iterate, as scikit-learn


def _shaped(beta, p, binary):
    if binary:
        return beta[None, :p].copy(), beta[p:].copy()
    return beta[:, :p].copy(), beta[:, p].copy()
