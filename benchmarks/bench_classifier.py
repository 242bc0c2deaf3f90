"""The region classifier's solver against scikit-learn's, on the problems a model search poses.

``python -m benchmarks classifier [--repeats=N]``

Every learned partition ends in a multinomial logistic regression (``fit_linear_partition``),
fitted hundreds of times in one search: the hard EM of ``switched`` refits it at every step,
warm-started from the previous step's classifier after some rows changed region, with up to a
few dozen regions; the partition learner's refinement does the same with a handful. Here each
problem is a set of rows drawn around random centres in 4 dimensions, labelled by the nearest
centre, then 3 % of them (those nearest a boundary) moved to the region across it and 1 % to a
random region (what a hard-EM step does, with some noise), fitted cold and then warm from the
classifier of the unmoved labels, by hwpts's Newton solver
(:mod:`hwpts.identification.partition.logistic`) and by scikit-learn's ``LogisticRegression``
(Newton-Cholesky, the same ``C`` and tolerance), best of ``--repeats`` runs each. Printed: the
times, their ratio, and the largest difference of the two solutions' scores (up to the constant
the multinomial intercepts share) relative to the largest score.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

C = 1e4
TOL = 1e-8
PROBLEMS = [(1500, 2), (1500, 3), (1500, 6), (1500, 10), (1500, 14), (1500, 20), (6000, 3), (6000, 6), (6000, 10)]


def _problem(n, k, seed):
    g = np.random.default_rng(seed)
    centres = g.normal(size=(k, 4))
    Z = g.normal(size=(n, 4))
    d2 = ((Z[:, None, :] - centres[None]) ** 2).sum(-1)
    order = np.argsort(d2, axis=1)
    labels, second = order[:, 0], order[:, 1]
    # a hard-EM step: the rows nearest a boundary (3 % of the rows with the smallest margin) move
    # to the region on its other side, and 1 % of the rows to a random region (noise)
    margin = d2[np.arange(n), second] - d2[np.arange(n), labels]
    moved = labels.copy()
    near = np.argsort(margin)[: int(0.03 * n)]
    moved[near] = second[near]
    noise = g.random(n) < 0.01
    moved[noise] = g.integers(0, k, int(noise.sum()))
    Z = (Z - Z.mean(0)) / Z.std(0)
    return Z, np.searchsorted(np.unique(labels), labels), np.searchsorted(np.unique(labels), moved)


def _sklearn(Z, y, start=None):
    from sklearn.linear_model import LogisticRegression

    clf = LogisticRegression(C=C, solver="newton-cholesky", max_iter=100, tol=TOL)
    if start is not None:
        clf.set_params(warm_start=True)
        clf.coef_, clf.intercept_ = start
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clf.fit(Z, y)
    return clf.coef_, clf.intercept_


def _ours(Z, y, start=None):
    from hwpts.identification.partition.logistic import newton_logistic

    k = int(y.max()) + 1
    coef, icpt = (None, None) if start is None else start
    fitted = newton_logistic(Z, y, k, C, tol=TOL, max_iter=100, coef=coef, intercept=icpt)
    if fitted is None:
        raise RuntimeError("the Newton solver could not step on a benchmark problem")
    return fitted[0], fitted[1]


def _best(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def _difference(Z, a, b):
    sa, sb = Z @ a[0].T + a[1], Z @ b[0].T + b[1]
    if sa.shape[1] > 1:
        sa, sb = sa - sa.mean(1, keepdims=True), sb - sb.mean(1, keepdims=True)
    return float(np.max(np.abs(sa - sb)) / np.max(np.abs(sb)))


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    repeats = 3
    for a in argv:
        if a.startswith("--repeats="):
            repeats = max(1, int(a.split("=", 1)[1]))
    print(f"region classifier: multinomial logistic regression, C = {C:g}, tol = {TOL:g}, 4 features; "
          f"best of {repeats}; cold = from zero, warm = from the classifier before 4 % of the labels moved")
    print(f"{'rows':>6} {'regions':>7}  {'start':5} {'hwpts ms':>9} {'sklearn ms':>10} {'ratio':>6} {'max score diff':>15}")
    ratios = []
    for n, k in PROBLEMS:
        Z, labels, moved = _problem(n, k, seed=n + k)
        start_ours, start_sk = _ours(Z, labels), _sklearn(Z, labels)
        for name, s_ours, s_sk in (("cold", None, None), ("warm", start_ours, start_sk)):
            t_ours, ours = _best(lambda: _ours(Z, moved, s_ours), repeats)
            t_sk, theirs = _best(lambda: _sklearn(Z, moved, s_sk), repeats)
            ratios.append(t_sk / t_ours)
            print(f"{n:6d} {k:7d}  {name:5} {1e3 * t_ours:9.2f} {1e3 * t_sk:10.2f} {t_sk / t_ours:5.1f}x "
                  f"{_difference(Z, ours, theirs):15.1e}")
    print(f"median ratio {np.median(ratios):.1f}x (scikit-learn's time over hwpts's), "
          f"from {min(ratios):.1f}x to {max(ratios):.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
