"""``hinging``: a continuous PWA map of hinging hyperplanes (Breiman 1993), its regions the hinges' sides.

A continuous piecewise-affine map of the regressors ``x`` (the standardised ``z``) with ``J`` hinges::

    f(z) = a' z + c + sum_j beta_j max(0, w_j' z + b_j)

is affine on each cell of the hinges' arrangement, and continuous across every boundary: the
boundaries are where the pieces meet, not a classifier's line drawn between the training samples
of two modes. Where the system is continuous (a saturation, a dead zone, a tank that empties and
overflows) that is what decides the boundaries. On the tank of ``python -m benchmarks textbook``
(``y(k) = min(10, max(0, y(k-1) + 0.2 u(k-1)))``, the true orders, 3 regions), whose threshold split on
``y(k-1)`` cannot leave the empty tank (its lower piece maps every input to ~0), the free-run fit on
the noise-free validation records over seeds 0-4 was (``--methods --seeds=5`` prints the rows,
``--samples=300`` the first):

=========  ==================================  ==================================
samples    ``hinging``                         ``threshold-alternating`` / ``threshold``
=========  ==================================  ==================================
300        94.4, 47.0, diverged, -202.5, 56.3  -350.4 .. 32.1 / -279.4 .. -63.9
3,000      98.4, 94.8, 86.1, 96.2, 98.2        98.6, 86.0, 85.4, 78.9, 96.7 / < -56
=========  ==================================  ==================================

On the zoo's continuous maps (``../shared/benchmarks/pwarx_zoo.py``, told the number of regions,
seeds 0-4, one-step fit on noise-free validation; a script not kept): ``hharx_roll`` (a hinge, 40 samples) 100.0 % on
every seed (``alternating`` 98.8-99.9, ``threshold`` 88.2-91.1); ``parc_sin2d`` (a smooth surface,
10 regions) median 91.1 % (``alternating`` 92.2, ``threshold`` 61.0): nine hinges crossing in the
plane make more pieces than the 10 regions kept (with every populated pattern a region, as a first
version did, 96.0 %, on many more regions).

It is not raced by the model search (:class:`~hwpts.identification.PWARXSearch`; give it in
``methods`` or fit it alone). Tried with first versions of this module, not kept: raced at every count, it won Silverbox's
search with 11 regions (test RMSE 3.33 / 0.90 mV against the output powers' 0.41 / 0.29) and
``benchmarks unseen``'s third-order system (91.9 % against 95.2 %); raced only where the threshold
split's free run is worse than none (as ``threshold-alternating``), the held-out blocks chose it with
7-10 regions on the tank and the search's median over 5 seeds fell from 94.0 % to 81.3 %.

``n_regions`` asks for ``n_regions - 1`` hinges: two parallel hinges make the three pieces of a
saturation on both sides. Hinges that cross inside the data make more sign patterns (up to
``2 ** (n_regions - 1)``); the ``n_regions`` most populated are the regions, the rows of the others
go to the region whose inequalities they violate least (the model is then continuous only where
its kept pieces meet). The hinges are fitted by variable projection (Golub & Pereyra 1973):
given the hinges ``(w_j, b_j)`` the affine part and the ``beta_j`` are a least-squares solve, so
a trust-region least-squares solver (scipy's ``least_squares``) moves the hinges only, on the
residual of that solve, with Kaufman's (1975) Jacobian. The starts are ``n_starts`` random
hinges, each through a random training row; the best end (least squared residual) is kept.

The regions are the hinges' sign patterns that hold at least a region's worth of training rows
(``p + 2`` for ``p`` regressors), each the polyhedron of its pattern; a row of a pattern with fewer
rows goes to the region whose inequalities it violates least (:class:`RegionPartition`). The
estimator then fits each region's affine model by least squares, as for every method (the
continuity is the boundaries', the local models are free).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular
from scipy.optimize import least_squares

from hwpts.errors import ParameterError
from hwpts.identification.partition import RegionPartition
from hwpts.identification.partition.polyhedra import varying_columns
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter

__all__ = ["HingingSegmenter", "fit_hinges"]

TOL = 1e-5  # relative change of the residual / the hinges that ends a start (the boundaries need no more)
JOINT_HINGES = 10  # hinges fitted together from random starts; more are added one at a time (fit_hinges)
START_WORK = 16000  # rows x starts of the automatic number of starts (HingingSegmenter.starts)
MAX_ROWS = 2000  # rows the hinges are fitted on (a seeded subsample beyond): the hinges need no more


def _design(Za, Zh, W, b):
    """``[Za, 1, max(0, Zh W' + b)]`` and the hinges' activity ``Zh W' + b > 0``."""
    pre = Zh @ W.T + b
    active = pre > 0.0
    return np.column_stack([Za, np.ones(len(Za)), np.where(active, pre, 0.0)]), active


def _projection(Za, Zh, t, W, b):
    """``(theta, residual, Q, active)`` of the least-squares solve given the hinges ``(W, b)``."""
    A, active = _design(Za, Zh, W, b)
    Q, R = np.linalg.qr(A)
    diag = np.abs(np.diag(R))
    if R.shape[0] == R.shape[1] and diag.min() > 1e-9 * diag.max():
        theta = solve_triangular(R, Q.T @ t)
    else:  # a hinge beside every row (or none) is collinear with the affine part: the minimum-norm solve
        theta = np.linalg.lstsq(A, t, rcond=None)[0]
    return theta, t - A @ theta, Q, active


def _least_squares(Za, Zh, t, starts, max_nfev):
    """``(sse, W, b)``: the best end of trust-region runs on the variable-projection residual of
    the hinges over ``Zh`` (the affine part over ``Za``), one from each ``(W, b)`` of ``starts``.

    A hinge's scale is free (``max(0, c w' z + c b) = c max(0, w' z + b)`` for ``c > 0``): one
    residual row per hinge, ``||w_j|| - 1``, fixes it without moving the fit, so that the Jacobian
    has full rank (rank-deficient, the same start ended in different hinges from one run to the
    next)."""
    n, d = Zh.shape
    da = Za.shape[1]
    J = starts[0][0].shape[0]
    weight = np.sqrt(n)  # the norm rows' weight: any positive one leaves the optimum where it is

    def split(x):
        return x[:J * d].reshape(J, d), x[J * d:]

    cache = {}

    def solve(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = _projection(Za, Zh, t, *split(x))
        return cache[key]

    def residual(x):
        W = split(x)[0]
        return np.concatenate([solve(x)[1], weight * (np.linalg.norm(W, axis=1) - 1.0)])

    def jacobian(x):
        W = split(x)[0]
        theta, _, Q, active = solve(x)
        beta = theta[da + 1:]
        # d(A theta)/d(w_jk) = beta_j [active_j] z_k, d/d(b_j) = beta_j [active_j]; Kaufman's
        # Jacobian of the projected residual: -(I - Q Q') of those columns
        act = active * beta  # (n, J)
        G = np.concatenate([(act[:, :, None] * Zh[:, None, :]).reshape(n, J * d), act], axis=1)
        norms = np.zeros((J, J * d + J))
        for j in range(J):
            norms[j, j * d:(j + 1) * d] = weight * W[j] / max(np.linalg.norm(W[j]), 1e-300)
        return np.vstack([-(G - Q @ (Q.T @ G)), norms])

    best = None
    for W0, b0 in starts:
        sol = least_squares(residual, np.concatenate([W0.ravel(), b0]), jac=jacobian, method="trf",
                            max_nfev=max_nfev, ftol=TOL, xtol=TOL)
        sse = float(sol.fun[:n] @ sol.fun[:n])
        if best is None or sse < best[0]:
            best = (sse, *split(sol.x))
    return best


def _random_hinges(Zh, count, rng):
    """``count`` hinges of random unit directions, each through a random row of ``Zh``."""
    n, d = Zh.shape
    W = rng.standard_normal((count, d))
    W /= np.linalg.norm(W, axis=1, keepdims=True)
    return W, -np.einsum("jd,jd->j", W, Zh[rng.choice(n, count, replace=n < count)])


def fit_hinges(Za, t, n_hinges: int, rng, n_starts: int = 4, max_nfev: int = 60, Zh=None):
    """``(W, b, theta, sse)``: ``n_hinges`` hinges ``max(0, w_j' z + b_j)`` over the columns ``Zh``
    (rows of ``W``, ``b``; default ``Za``) and the least-squares ``theta`` of ``[Za, 1, hinges]``
    on the targets ``t`` (module doc).

    Up to :data:`JOINT_HINGES` hinges: the best of ``n_starts`` runs from random hinges, all
    moved together. More: stagewise, as Breiman's hinge finding (1993): each hinge in turn the best
    of ``n_starts`` runs that move it alone, the earlier ones held (a run's cost grows with the
    square of the hinges it moves; on 2,000 of Silverbox's rows, 5 regressors, 8 starts: 10 hinges
    2.4 s together, 2.0 s stagewise, squared residual 0.571 and 0.543; 19 hinges 6.7 and 3.8 s,
    0.499 and 0.505)."""
    Zh = Za if Zh is None else Zh
    J = int(n_hinges)
    if J <= JOINT_HINGES:
        _, W, b = _least_squares(Za, Zh, t, [_random_hinges(Zh, J, rng) for _ in range(int(n_starts))], max_nfev)
    else:
        d = Zh.shape[1]
        W, b = np.zeros((0, d)), np.zeros(0)
        for _ in range(J):
            held = np.maximum(0.0, Zh @ W.T + b)  # the earlier hinges, columns of the affine part
            _, w, c = _least_squares(np.column_stack([Za, held]), Zh, t,
                                     [_random_hinges(Zh, 1, rng) for _ in range(int(n_starts))], max_nfev)
            W, b = np.vstack([W, w]), np.concatenate([b, c])
    theta, residual, _, _ = _projection(Za, Zh, t, W, b)
    return W, b, theta, float(residual @ residual)


def _sign_partition(W, b, patterns) -> RegionPartition:
    """The polyhedra of the hinges' sign ``patterns`` (rows of 0/1): ``w_j' x + b_j >= 0`` where
    the pattern's ``j`` is 1, ``<= 0`` where it is 0."""
    H, g = [], []
    for p in patterns:
        s = np.where(p, -1.0, 1.0)  # side 1: -(w x + b) <= 0; side 0: (w x + b) <= 0
        H.append(s[:, None] * W)
        g.append(s * b)
    return RegionPartition(H, g, kind="hinges")


class HingingSegmenter(Segmenter):
    """Regions of a continuous PWA map: ``n_regions - 1`` hinging hyperplanes fitted to the data
    (module doc); the partition is the hinges' sign patterns that hold training rows.

    Parameters
    ----------
    n_starts : int or "auto"
        Random starts of the hinges' least-squares fit (the best end is kept); ``"auto"``:
        16 on up to 1,000 rows, down to 8 on 2,000, the most a fit uses (:meth:`starts`).
    max_nfev : int
        Residual evaluations of each start's fit.
    """

    name = "hinging"
    returns_partition = True
    #: the hinges' directions take only a PWARX's ``partition_columns`` (``segment(columns=...)``)
    restricts_columns = True

    def __init__(self, *, n_starts="auto", max_nfev: int = 60):
        self.n_starts = n_starts
        self.max_nfev = max_nfev

    def check_params(self) -> None:
        """One line naming a setting that is not an int >= 1 (``n_starts`` may be ``"auto"``)."""
        for key in ("n_starts", "max_nfev"):
            value = getattr(self, key)
            if key == "n_starts" and value == "auto":
                continue
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ParameterError(f"hinging: {key} must be {'auto or ' if key == 'n_starts' else ''}an int >= 1, "
                                     f"got {value!r}")

    def starts(self, n_rows: int) -> int:
        """The number of starts: ``n_starts``, or with ``"auto"`` :data:`START_WORK` rows' worth
        (between 4 and 16): few rows cost little, and on the 3,000-sample tank 4 starts left one seed of
        five at 46.8 % free-run fit where 8 reached 86.1 %."""
        if self.n_starts != "auto":
            return int(self.n_starts)
        return int(np.clip(START_WORK // max(n_rows, 1), 4, 16))

    def segment(self, X, y, n_regions, structure, rng, columns=None) -> SegmentationResult:
        """Fit ``n_regions - 1`` hinges to the regressor rows ``X`` and targets ``y`` (their
        directions over ``columns`` only, when given: a PWARX's ``partition_columns``) and return
        the regions of their sign patterns, with their partition (module doc)."""
        self.check_params()
        X, y, rng = self._check_rows(X, y, rng)
        self._check_regions(n_regions, X.shape[0])
        n, p = X.shape
        rows = np.arange(n) if n <= MAX_ROWS else np.sort(rng.choice(n, MAX_ROWS, replace=False))
        mean, sd = X[rows].mean(axis=0), X[rows].std(axis=0)
        # a column constant to rounding (an input held over these rows) takes no part: scaled by its
        # rounding-level spread, its hinge weight grew to 1e18 and a 1e-12 change moved rows
        varies = varying_columns(X[rows], sd)
        allowed = np.zeros(p, dtype=bool)
        allowed[list(range(p)) if columns is None else list(columns)] = True
        hinged = np.flatnonzero(varies & allowed)
        if n_regions == 1 or hinged.size == 0:
            return SegmentationResult(np.zeros(n, dtype=np.int64), 1, RegionPartition.single(p), refine=False,
                                      info={"hinges": 0})
        Za = (X[rows][:, varies] - mean[varies]) / sd[varies]
        Zh = (X[rows][:, hinged] - mean[hinged]) / sd[hinged]
        ys = y[rows].std() or 1.0
        W, b, _, sse = fit_hinges(Za, (y[rows] - y[rows].mean()) / ys, n_regions - 1, rng, self.starts(len(rows)),
                                  self.max_nfev, Zh=Zh)
        # the hinges over the raw regressors: w' (x - mean) / sd + b
        Wx = np.zeros((W.shape[0], p))
        Wx[:, hinged] = W / sd[hinged]
        bx = b - Wx @ mean
        patterns, counts = np.unique((X @ Wx.T + bx) > 0.0, axis=0, return_counts=True)
        order = np.argsort(-counts, kind="stable")  # the most populated region first
        patterns, counts = patterns[order], counts[order]
        # at most n_regions regions, the most populated patterns, each with a region's worth of rows
        # (p + 2); the rows of the others go to the region they violate least (crossing hinges make
        # up to 2 ** (n_regions - 1) patterns: 20 asked on Silverbox made 263, and a fit of minutes).
        # Counted again as the partition assigns them: a row on a hinge goes to the first region
        # that holds it, not to its pattern
        keep = (np.arange(len(patterns)) < n_regions) & (counts >= p + 2)
        keep[0] = True
        while True:
            partition = _sign_partition(Wx, bx, patterns[keep])
            labels = partition.predict(X)
            held = np.bincount(labels, minlength=partition.n_regions)
            if held.min() >= p + 2 or partition.n_regions == 1:
                break
            keep[np.flatnonzero(keep)[int(np.argmin(held))]] = False
        dropped = int((~keep).sum())
        return SegmentationResult(labels, partition.n_regions, partition, refine=False,
                                  info={"hinges": int(n_regions - 1), "objective": round(sse / len(rows), 8),
                                        "patterns_dropped": dropped})
