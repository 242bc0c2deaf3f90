"""``alternating``: assign each sample to its best local model, refit, repeat (k-LinReg / PARC style).

In the spirit of Lauer's k-LinReg (2013) and Bemporad's PARC (2023): starting from an initial
assignment, alternate

1. least squares per region (eq. 17) on standardised regressors,
2. reassignment of every sample to the region minimising::

       (y_k - phi_k' theta_i)^2 / sigma^2  +  gamma * ||z_k - c_i||^2 / n

   where ``sigma^2`` is the current mean squared residual, ``z_k`` the standardised regressor and
   ``c_i`` the centroid of region ``i``. The second (region-separability) term keeps the regions
   compact so a linear classifier can separate them, and decides between modes that predict the
   same value (equal parameters on disjoint regions),

until the assignment is stable. Several restarts keep the best objective: the first from the
Ferrari-Trecate clustering, the others from k-means of ``[z, y]`` with different seeds. On more
than 4,000 rows the starts run on a random subset of 4,000 rows, and there they begin in turn from
k-means and from random parameter vectors, each row given to the one predicting it best (the
starts of Lauer's k-LinReg, 2013), as many as Lauer's rule asks for (at most 12); the best of the
random-parameter starts is kept over the others' best only when its objective is clearly lower
(:func:`preferred_end`: a minimum 6 % lower, from modes that interleave in the regressor space, cost
the identification run of ``hwpts reproduce`` 13 points on its validation cases). k-means of
thousands of rows lands in much the same place whatever its seed, and where that place is a poor
minimum every k-means start finds it again: with 3 starts (clustering and two k-means, the
earlier budget on large data) the zoo's ``pwarx_random`` stopped at objectives of 0.028-0.035,
the true modes' 0.008, one-step fit 25-28 %, on one of 6 fits at 20,000 samples and one of 6 at
300,000 (with a fourth start from random parameters, still on one of 2 at 100,000: all four at
0.027-0.053); with the starts in turn every fit found the modes' objective (8 fits at 20,000
samples, 8 at 100,000, 6 at 300,000), for 0.15 s more a fit at 20,000 samples. Not on fewer
rows: there the starts are already up to 12 and k-means of them differs from seed to seed, and
random-parameter starts in place of every other one (tried) kept regions that generalise worse:
the zoo's ``parc_sin2d`` (800 rows) then stopped its search at 2-3 regions, one-step fit 62-63 %
against 95-96 % with 15-18 regions. Optionally
(``anneal=(10, 3)``) each start is first alternated with a larger separability weight (gamma x 10,
then x 3), which merges fragments of a mode scattered over the regressor space into compact
regions, and then with ``gamma`` itself (a continuation). On synthetic system 2 (five modes
from 100 samples) plain starts land in a worse local minimum on 3 of 20 data sets and lose a mode;
the continuation finds all five on all 20. It is off by default because on real data it moves the
chosen local minimum as much: it changes the hydraulic actuator's blocked selection from a model
scoring 79.2 % on the test part to one scoring 27.1 %, with a better cross-validated score. On large data
the restarts run on a random subset of 4,000 rows and only the best is carried to all rows. A region
that loses almost all samples is re-seeded with the worst-fitted samples. Everything is vectorised.
"""

from __future__ import annotations

import numba
import numpy as np

from hwpts._linalg import lu_factor, lu_solve
from hwpts.errors import ParameterError
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter, kmeans_labels, standardize
from hwpts.identification.settings import check_count, check_number


def _fit_thetas(Phi, ys, labels, s, ridge):
    p = Phi.shape[1]
    theta = np.zeros((s, p))
    for i in range(s):
        mask = labels == i
        A = Phi[mask]
        G = A.T @ A + ridge * max(mask.sum(), 1) * np.eye(p)
        theta[i] = np.linalg.solve(G, A.T @ ys[mask])
    return theta


@numba.njit(cache=True, nogil=True)
def _alternate_kernel(Phi, ys, Z, labels, s, gamma, max_iter, ridge):  # pragma: no cover - compiled
    """The alternation loop of :func:`alternate` compiled (same steps, one pass over the rows per
    step instead of a dozen array operations): returns (labels, iterations). The regions' normal
    equations and centroid sums are accumulated over all rows once, then updated with the rows
    that change region only (late steps move a few rows: on Silverbox's 20,000 training rows the
    accumulation was half of each step)."""
    n, p = Phi.shape
    d = Z.shape[1]
    nf = max(d, 1)
    labels = labels.copy()
    theta = np.zeros((s, p))
    cent = np.zeros((s, d))
    cost = np.empty((n, s))
    new = np.empty(n, dtype=np.int64)
    # running sums per region: the upper triangle of Phi'Phi, Phi'y, the rows' count and Z sums
    G = np.zeros((s, p, p))
    r = np.zeros((s, p))
    counts = np.zeros(s, dtype=np.int64)
    zsum = np.zeros((s, d))
    for k in range(n):
        _move_row(Phi, ys, Z, k, labels[k], 1.0, G, r, zsum)
        counts[labels[k]] += 1
    A = np.empty((p, p))
    piv = np.empty(p, dtype=np.int64)
    it = 0
    for it in range(1, max_iter + 1):
        # least squares per region (ridge * max(count, 1) on the diagonal)
        for i in range(s):
            for a in range(p):
                A[a, a] = G[i, a, a] + ridge * max(counts[i], 1)
                for b in range(a + 1, p):
                    A[a, b] = G[i, a, b]
                    A[b, a] = G[i, a, b]
            # (hwpts._linalg: np.linalg.solve here doubled the kernel's first compilation)
            if not lu_factor(A, piv):
                return labels, -1  # singular: said by the caller (a raise here compiles slowly)
            for a in range(p):  # (an element loop: a slice assignment compiles numba's shape checks)
                theta[i, a] = r[i, a]
            lu_solve(A, piv, theta[i])
            for j in range(d):
                cent[i, j] = zsum[i, j] / counts[i] if counts[i] else Z[0, j]
        # residuals, their mean over the assigned rows, and the cost of every row in every region
        sigma2 = 0.0
        for k in range(n):
            for i in range(s):
                e = ys[k]
                for a in range(p):
                    e -= Phi[k, a] * theta[i, a]
                cost[k, i] = e * e
            sigma2 += cost[k, labels[k]]
        sigma2 = sigma2 / n + 1e-12
        for k in range(n):
            best = 0
            for i in range(s):
                dist = 0.0
                for j in range(d):
                    dist += (Z[k, j] - cent[i, j]) ** 2
                cost[k, i] = cost[k, i] / sigma2 + gamma * dist / nf
                if cost[k, i] < cost[k, best]:
                    best = i
            new[k] = best
        newcounts = np.zeros(s, dtype=np.int64)
        for k in range(n):
            newcounts[new[k]] += 1
        taken = np.zeros(0, dtype=np.bool_)
        for i in range(s):
            if newcounts[i] < p:  # re-seed starving regions with the worst-fitted samples
                if taken.size == 0:
                    assigned = np.empty(n)
                    for k in range(n):
                        assigned[k] = cost[k, new[k]]
                    taken = np.zeros(n, dtype=np.bool_)
                for _ in range(p):  # the p worst rows not taken yet, the first of equals first
                    worst = -1
                    for k in range(n):
                        if not taken[k] and (worst < 0 or assigned[k] > assigned[worst]):
                            worst = k
                    if worst < 0:
                        break
                    taken[worst] = True
                    new[worst] = i
        same = True
        for k in range(n):
            if new[k] != labels[k]:
                same = False
                _move_row(Phi, ys, Z, k, labels[k], -1.0, G, r, zsum)
                _move_row(Phi, ys, Z, k, new[k], 1.0, G, r, zsum)
                counts[labels[k]] -= 1
                counts[new[k]] += 1
                labels[k] = new[k]
        if same:
            break
    return labels, it


@numba.njit(cache=True, nogil=True, inline="always")
def _move_row(Phi, ys, Z, k, i, sign, G, r, zsum):  # pragma: no cover - compiled
    """Add (``sign`` 1) or remove (-1) row ``k`` from region ``i``'s running sums."""
    p = Phi.shape[1]
    for a in range(p):
        v = sign * Phi[k, a]
        r[i, a] += v * ys[k]
        for b in range(a, p):
            G[i, a, b] += v * Phi[k, b]
    for j in range(Z.shape[1]):
        zsum[i, j] += sign * Z[k, j]


def _objective(Phi, ys, Z, labels, s, gamma, ridge, nf):
    """The alternation's objective at ``labels``: mean squared residual plus gamma sigma^2 times the
    mean squared distance to the region's feature centroid."""
    theta = _fit_thetas(Phi, ys, labels, s, ridge)
    R = (ys - np.einsum("ij,ij->i", Phi, theta[labels])) ** 2
    cent = np.array([Z[labels == i].mean(axis=0) if np.any(labels == i) else Z[0] for i in range(s)])
    D = ((Z - cent[labels]) ** 2).sum(axis=1) / nf
    sigma2 = float(R.mean()) + 1e-12
    return float(np.mean(R) + gamma * sigma2 * np.mean(D))


def alternate(Phi, ys, Z, labels, s, gamma=1.0, max_iter=50, ridge=1e-8):
    """Run the alternation from ``labels``; returns (labels, objective, iterations)."""
    n, p = Phi.shape
    nf = max(Z.shape[1], 1)
    labels, it = _alternate_kernel(np.ascontiguousarray(Phi, dtype=float), np.ascontiguousarray(ys, dtype=float),
                                   np.ascontiguousarray(Z, dtype=float), np.asarray(labels, dtype=np.int64),
                                   int(s), float(gamma), int(max_iter), float(ridge))
    if it < 0:
        raise np.linalg.LinAlgError("Singular matrix")  # as np.linalg.solve says it
    return labels, _objective(Phi, ys, Z, labels, s, gamma, ridge, nf), it


def _alternate_numpy(Phi, ys, Z, labels, s, gamma=1.0, max_iter=50, ridge=1e-8):
    """The alternation in numpy (the reference the compiled kernel is tested against)."""
    n, p = Phi.shape
    nf = max(Z.shape[1], 1)
    labels = labels.copy()
    it = 0
    for it in range(1, max_iter + 1):
        counts = np.bincount(labels, minlength=s)
        theta = _fit_thetas(Phi, ys, labels, s, ridge)
        R = (ys[:, None] - Phi @ theta.T) ** 2
        sigma2 = float(np.mean(R[np.arange(n), labels])) + 1e-12
        cent = np.zeros((s, Z.shape[1]))
        for i in range(s):
            cent[i] = Z[labels == i].mean(axis=0) if counts[i] else Z[0]
        D = ((Z[:, None, :] - cent[None]) ** 2).sum(axis=2) / nf
        cost = R / sigma2 + gamma * D
        new = np.argmin(cost, axis=1)
        counts = np.bincount(new, minlength=s)
        small = np.flatnonzero(counts < p)
        if small.size:  # re-seed starving regions with the worst-fitted samples
            worst = np.argsort(-cost[np.arange(n), new], kind="stable")
            taken = 0
            for i in small:
                new[worst[taken : taken + p]] = i
                taken += p
        if np.array_equal(new, labels):
            break
        labels = new
    return labels, _objective(Phi, ys, Z, labels, s, gamma, ridge, nf), it


def scaled_problem(X, y):
    """``(Z, ys, Phi)``: the standardised regressors, the standardised output and ``[Z, 1]``, on
    which the alternation runs."""
    Z = standardize(X)
    ys = (y - y.mean()) / (y.std() or 1.0)
    return Z, ys, np.hstack([Z, np.ones((X.shape[0], 1))])


def random_parameter_labels(Phi, ys, s, rng) -> np.ndarray:
    """k-LinReg's start (Lauer 2013): ``s`` parameter vectors drawn from a standard normal (the
    regressors and the output standardised), each row labelled with the one whose prediction is
    nearest its output."""
    theta = rng.standard_normal((s, Phi.shape[1]))
    return np.argmin((ys[:, None] - Phi @ theta.T) ** 2, axis=1).astype(np.int64)


SUBSET = 4000  # rows used by the clustering start on large data sets
ANNEAL_ITER = 15  # alternation steps of each continuation stage (it only has to find the basin)
AUTO_MIN_RESTARTS = 3
AUTO_MAX_RESTARTS = 12
SAME_OBJECTIVE = 1e-6  # relative difference under which two starts reached the same minimum
RANDOM_START_GAIN = 0.1  # large data: how much lower a random start's objective must be (preferred_end)


def restarts_needed(objectives, confidence: float = 0.99) -> int:
    """Starts needed so that the best minimum is found with ``confidence``, from the share of the
    starts so far that reached it (Lauer 2013's success probability, estimated online)."""
    obj = np.asarray(objectives, dtype=float)
    best = obj.min()
    hits = int(np.sum(obj <= best + SAME_OBJECTIVE * max(abs(best), 1e-300)))
    p = hits / obj.size
    if p >= 1.0:
        return obj.size
    return int(np.ceil(np.log(1.0 - confidence) / np.log(1.0 - p)))


def preferred_end(structured, random):
    """The end ``(labels, objective, iterations, restart)`` kept of the clustering and k-means
    starts' best (``structured``) and the random-parameter starts' best (``random``, or None): the
    random one only when its objective is lower by more than :data:`RANDOM_START_GAIN` (relative).
    Those starts escape a basin that every k-means start finds, far above the true modes (the zoo's
    ``pwarx_random``: 0.028-0.035 against the true modes' 0.008); their modes need not be compact,
    and a slightly lower objective from modes that interleave in the regressor space is a model no
    linear partition reproduces (the identification run of ``hwpts reproduce``, 24,000 samples, 5
    regions: a random start 6.1 % below the clustering start's objective validated at 88.3 / 78.1 /
    72.0 % on cases 2-4, the clustering start's minimum at 94.8 / 94.7 / 91.6 %)."""
    if random is not None and random[1] < (1.0 - RANDOM_START_GAIN) * structured[1]:
        return random
    return structured


class AlternatingSegmenter(Segmenter):
    """Alternating assignment/least squares with a separability term and restarts (module doc).

    Parameters
    ----------
    n_restarts : int or "auto"
        Number of starts (the first from ``clustering``, then k-means seeds; on more than 4,000 rows
        k-means and random parameters in turn). ``"auto"`` follows
        Lauer's success-probability argument (Lauer 2013, "Estimating the probability of success of
        a simple algorithm for switched linear regression"): with ``m`` of ``r`` starts reaching the
        best objective so far, the chance that one start succeeds is about ``p = m / r``, and
        ``log(0.01) / log(1 - p)`` starts find the best minimum with 99 % probability; starts run
        until that many were made (at least 3, at most ``AUTO_MAX_RESTARTS``; fewer on 1,000-4,000
        rows, where each start costs more; above 4,000 rows they run on a subset of 4,000). The
        default: a fixed 4 left a noise-free two-mode system unrecovered about once in 1,000
        random draws (all four starts in one 0.18 minimum, the tenth start at the exact one).
    gamma : float
        Weight of the region-separability term (in units of the residual variance).
    max_iter : int
        Alternation steps per start.
    anneal : tuple of float
        Multipliers of ``gamma`` for continuation stages run before the final alternation, e.g.
        ``(10.0, 3.0)``; ``()`` (default) runs the plain alternation.
    """

    name = "alternating"
    learns_partition = True

    def __init__(self, *, n_restarts: int | str = "auto", gamma: float = 1.0, max_iter: int = 50,
                 anneal: tuple = ()):
        self.n_restarts = n_restarts
        self.gamma = gamma
        self.max_iter = max_iter
        self.anneal = anneal

    def _restarts(self, X, y, Z, ys, Phi, s, structure, rng, mixed=False):
        """All starts on (X, y); the best (labels, objective, iterations, restart, objectives).
        ``mixed`` (the subset of large data): the starts after the first from k-means and random
        parameters in turn, as many as Lauer's rule asks for."""
        from hwpts.identification.segmentation.clustering import ClusteringSegmenter

        best = best_random = None
        objectives = []
        auto = isinstance(self.n_restarts, str)
        if auto and self.n_restarts != "auto":
            raise ParameterError(f"alternating: n_restarts must be an int >= 1 or 'auto', got {self.n_restarts!r}")
        budget = AUTO_MAX_RESTARTS if auto else max(1, int(self.n_restarts))
        if auto and X.shape[0] > 1000 and not mixed:  # 1,000-4,000 rows: fewer starts, each dearer
            budget = max(AUTO_MIN_RESTARTS, int(AUTO_MAX_RESTARTS * 1000 / X.shape[0]))
        for r in range(budget):
            if auto and r >= AUTO_MIN_RESTARTS and r >= restarts_needed(objectives):
                break
            random_start = mixed and r > 0 and r % 2 == 0
            if r == 0:
                init = ClusteringSegmenter(n_init=3).segment(X, y, s, structure, rng).labels
            elif not random_start:
                init = kmeans_labels(np.column_stack([Z, ys]), s, rng, n_init=1)
            else:
                init = random_parameter_labels(Phi, ys, s, rng)
            for mult in tuple(float(a) for a in self.anneal):
                init, _, _ = alternate(Phi, ys, Z, init, s, self.gamma * mult, ANNEAL_ITER)
            labels, obj, it = alternate(Phi, ys, Z, init, s, self.gamma, self.max_iter)
            objectives.append(obj)
            end = (labels, obj, it, r)
            if random_start:
                if best_random is None or obj < best_random[1]:
                    best_random = end
            elif best is None or obj < best[1]:
                best = end
        return (*preferred_end(best, best_random), objectives)

    def check_params(self) -> None:
        """``n_restarts``, ``gamma``, ``max_iter`` and ``anneal`` (see :meth:`Segmenter.check_params`)."""
        check_count(self.n_restarts, "n_restarts", 1, "alternating: ", allow=("auto",))
        check_number(self.gamma, "gamma", owner="alternating: ")
        check_count(self.max_iter, "max_iter", 1, "alternating: ")
        try:
            anneal = tuple(float(a) for a in self.anneal)
        except (TypeError, ValueError):
            anneal = None
        if anneal is None or not all(np.isfinite(a) and a > 0 for a in anneal):
            raise ParameterError(f"alternating: anneal must be a list of numbers > 0 (multiples of gamma), "
                                 f"got {self.anneal!r}")

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """Labels from alternating assignment and least squares with restarts (see the module docstring)."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        self._check_regions(n_regions, X.shape[0])
        s = n_regions
        n = X.shape[0]
        if s == 1:
            return SegmentationResult(np.zeros(n, dtype=np.int64), 1)
        Z, ys, Phi = scaled_problem(X, y)
        if n <= SUBSET:
            labels, obj, it, r, objectives = self._restarts(X, y, Z, ys, Phi, s, structure, rng)
        else:
            # large data: every start on a random subset, the best one extended to all rows by one
            # assignment step, then alternated on all rows
            idx = np.sort(rng.choice(n, SUBSET, replace=False))
            sub, _, _, r, objectives = self._restarts(X[idx], y[idx], Z[idx], ys[idx], Phi[idx], s,
                                                       structure, rng, mixed=True)
            theta = _fit_thetas(Phi[idx], ys[idx], sub, s, 1e-8)
            R = (ys[:, None] - Phi @ theta.T) ** 2
            sigma2 = float(np.mean(R[idx, sub])) + 1e-12
            cent = np.array([Z[idx][sub == i].mean(axis=0) if np.any(sub == i) else Z[0] for i in range(s)])
            D = ((Z[:, None, :] - cent[None]) ** 2).sum(axis=2) / max(Z.shape[1], 1)
            init = np.argmin(R / sigma2 + self.gamma * D, axis=1)
            labels, obj, it = alternate(Phi, ys, Z, init, s, self.gamma, self.max_iter)
        return SegmentationResult(labels, s, info={"objective": obj, "iterations": it, "restart": r,
                                                   "objectives": objectives})
