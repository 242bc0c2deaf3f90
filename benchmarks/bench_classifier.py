"""The region classifier's solver against scikit-learn's, on the problems a model search poses.

``python -m benchmarks classifier [--repeats=N] [--no-search]``

Every learned partition ends in a multinomial logistic regression (``fit_linear_partition``),
fitted hundreds of times in one search: the hard EM of ``switched`` refits it at every step,
warm-started from the previous step's classifier, with up to a few dozen regions; the partition
learner's refinement does the same with a handful. Both solvers minimise scikit-learn's
``LogisticRegression(C=1e4)`` objective to the same tolerance: hwpts's Newton iteration
(:mod:`hwpts.identification.partition.logistic`) and scikit-learn's Newton-Cholesky.

1. Synthetic problems: rows drawn in 4 dimensions and labelled by the nearest of ``K`` random
   centres, then 3 % of them (those nearest a boundary) moved to the region across it and 1 % to
   a random region; each solver from zero, best of ``--repeats`` runs.
2. The problems of a search (skipped with ``--no-search`` or without the zoo,
   ``../shared/benchmarks/pwarx_zoo.py``): every classifier fit of one ``switched`` segmentation
   of the zoo variant ``rand_abcabc`` (10,000 samples, 3 modes on 6 slabs), recorded with its
   rows, labels and warm start, each refitted by both solvers from that start (once each),
   grouped by the number of regions.

Printed: the times, their ratio, and the largest difference of the two solutions' scores (up to
the constant the multinomial intercepts share) relative to the largest score.
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
    return Z, np.searchsorted(np.unique(labels), moved)


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


def _recorded_problems():
    """Every (rows, classes, regions, C, start) the solver met in one ``switched`` segmentation of
    the zoo's ``rand_abcabc`` variant, or None without the zoo."""
    from benchmarks.bench_zoo import VARIANTS, load_zoo, orders
    from hwpts.identification import PWARX
    from hwpts.identification.partition import polyhedra

    zoo = load_zoo()
    if zoo is None:
        return None
    d = zoo.pwarx_random(rng=0, **VARIANTS["rand_abcabc"])
    na, nb, nk, u = orders(d)
    recorded = []
    solver = polyhedra.newton_logistic

    def recording(Z, y, k, C_, tol=TOL, max_iter=100, coef=None, intercept=None):
        recorded.append((Z.copy(), np.asarray(y).copy(), k, C_, None if coef is None else (coef.copy(), intercept.copy())))
        return solver(Z, y, k, C_, tol=tol, max_iter=max_iter, coef=coef, intercept=intercept)

    polyhedra.newton_logistic = recording
    try:
        PWARX(output_order=na, input_order=nb, input_delay=nk, n_regions=3, segmentation="switched",
              random_state=0).fit(u, d.output)
    finally:
        polyhedra.newton_logistic = solver
    return recorded


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    repeats = 3
    for a in argv:
        if a.startswith("--repeats="):
            repeats = max(1, int(a.split("=", 1)[1]))
    print(f"region classifier: multinomial logistic regression, C = {C:g}, tol = {TOL:g}")
    print(f"1. synthetic problems, 4 features, from zero, best of {repeats}")
    print(f"{'rows':>6} {'regions':>7} {'hwpts ms':>9} {'sklearn ms':>10} {'ratio':>6} {'max score diff':>15}")
    ratios = []
    for n, k in PROBLEMS:
        Z, moved = _problem(n, k, seed=n + k)
        t_ours, ours = _best(lambda: _ours(Z, moved), repeats)
        t_sk, theirs = _best(lambda: _sklearn(Z, moved), repeats)
        ratios.append(t_sk / t_ours)
        print(f"{n:6d} {k:7d} {1e3 * t_ours:9.2f} {1e3 * t_sk:10.2f} {t_sk / t_ours:5.1f}x "
              f"{_difference(Z, ours, theirs):15.1e}")
    print(f"median ratio {np.median(ratios):.1f}x (scikit-learn's time over hwpts's), "
          f"from {min(ratios):.1f}x to {max(ratios):.1f}x")
    if "--no-search" in argv:
        return 0
    problems = _recorded_problems()
    if problems is None:
        print("2. skipped: the zoo (../shared/benchmarks/pwarx_zoo.py or $HWPTS_ZOO) was not found")
        return 0
    print(f"2. the {len(problems)} classifier fits of one switched segmentation of rand_abcabc "
          f"(10,000 samples), each from its recorded start, by number of regions")
    print(f"{'regions':>9} {'fits':>5} {'mean rows':>9} {'warm':>5} {'hwpts s':>8} {'sklearn s':>9} {'ratio':>6} {'max score diff':>15}")
    groups = {}
    for Z, y, k, C_, start in problems:
        t0 = time.perf_counter()
        ours = _ours(Z, y, start)
        t1 = time.perf_counter()
        theirs = _sklearn(Z, y, start)
        t2 = time.perf_counter()
        key = "2-5" if k <= 5 else ("6-10" if k <= 10 else "11+")
        g = groups.setdefault(key, [0, 0, 0, 0.0, 0.0, 0.0])
        g[0] += 1
        g[1] += Z.shape[0]
        g[2] += start is not None
        g[3] += t1 - t0
        g[4] += t2 - t1
        g[5] = max(g[5], _difference(Z, ours, theirs))
    total = [0.0, 0.0]
    for key in ("2-5", "6-10", "11+"):
        if key in groups:
            c, rows, warm, t_ours, t_sk, diff = groups[key]
            total[0] += t_ours
            total[1] += t_sk
            print(f"{key:>9} {c:5d} {rows / c:9.0f} {warm:5d} {t_ours:8.2f} {t_sk:9.2f} {t_sk / t_ours:5.1f}x {diff:15.1e}")
    print(f"all fits: hwpts {total[0]:.2f} s, scikit-learn {total[1]:.2f} s: {total[1] / total[0]:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
