"""``threshold``: regions split by thresholds on one regressor column (SETAR / TARX models).

The switching of many real systems depends on one signal crossing a level: a position where a
head touches a surface, a pressure where a valve opens, a level where a tank overflows. Such a
PWARX model is a *threshold* ARX model (Tong's SETAR/TARX, Tong 1990; Hansen 2000): with the
threshold variable ``x_c`` (a regressor column; by default the best one) and ordered thresholds
``t_1 < ... < t_{s-1}``, region ``i`` is ``{x : t_{i-1} < x_c <= t_i}`` (a polyhedron, eq. 9).

The thresholds are estimated by conditional least squares, *exactly*: sorting the rows by ``x_c``
turns every region into a contiguous block of sorted rows, and accumulating the normal equations
gives the residual sum of squares of any block from one small solve. The best ``s``-block split
(each block holding at least ``min_share`` of the rows and more rows than parameters) is then the
optimal segmentation of a sequence, found by dynamic programming (Bellman 1961; Bai & Perron 1998
for multiple structural breaks) in ``O(s G^2)`` for ``G`` candidate cuts: every position where
``x_c`` changes on small data (at most 400 rows) or when there are at most ``n_grid`` of them
(the split is then the global least-squares optimum); otherwise ``n_grid`` quantiles, and each
cut of the grid's optimum is then moved to the exact least-squares position between the grid
nodes around it (coordinate descent, one cut at a time: on 3,000 rows of a 4-piece static map
with jumps at -1, 0, 1 the grid alone put the cuts at -1.006, -0.004, 0.993, a noise-free
validation fit of 91.75 % instead of 99.94 %). With ``column=None`` every regressor column is
tried and the one with the smallest residual sum of squares (on the grid) wins; on large data with
more than two columns every column is first scored on a 50-cut grid and only the two best on the
full one. The result is deterministic (no random restarts) and the
partition is fixed (no boundary refinement): few boundary parameters, low variance, which suits
free-run simulation; on one-dimensional switching (a static map, or a system switching on one
signal) it is the least-squares estimate of the switching points, which no clustering method is.
"""

from __future__ import annotations

import numba
import numpy as np

from hwpts.errors import IdentificationError, ParameterError
from hwpts.identification.partition import RegionPartition
from hwpts.identification.segmentation.base import BoundedCache, SegmentationResult, Segmenter, fingerprint

__all__ = ["ThresholdSegmenter", "threshold_partition"]


def threshold_partition(column: int, thresholds, n_features: int) -> RegionPartition:
    """Regions ``t_{i-1} < x_column <= t_i`` (first region ``x <= t_1``, last ``x > t_{s-1}``)."""
    t = [float(v) for v in thresholds]
    e = np.zeros(n_features)
    e[column] = 1.0
    H, g = [], []
    for i in range(len(t) + 1):
        rows, offs = [], []
        if i > 0:  # x > t_{i-1}  <=>  -x + t_{i-1} <= 0 (boundary goes to the lower region first)
            rows.append(-e)
            offs.append(t[i - 1])
        if i < len(t):  # x <= t_i
            rows.append(e)
            offs.append(-t[i])
        H.append(np.array(rows).reshape(-1, n_features))
        g.append(np.array(offs))
    partition = RegionPartition(H, g, kind="thresholds")
    if all(a < b for a, b in zip(t[:-1], t[1:])):
        partition.cuts = (int(column), np.array(t))
    return partition


EXACT_ROWS = 400  # up to this many rows, every change of the threshold variable is a candidate cut
# floating-point work allowed for the block costs of one segmentation (every column): a grid of G
# cuts costs about G^2 / 2 solves of a p x p system per column, so on wide regressors (na = 100:
# 102 columns, p = 103) the grid is coarsened to fit (the cuts are refined exactly afterwards);
# at p = 10 and 9 columns the 200 default cuts use 0.3 % of it
GRID_FLOPS = 2e10
MIN_GRID = 16
# With more than SCREEN_KEEP columns to try on large data, every column is first scored on a grid of
# SCREEN_GRID cuts (a sixteenth of the block costs of 200) and only the SCREEN_KEEP best are scored
# on the full grid: on Silverbox (8 columns, 3 folds of 20,000 rows) the first split took 0.50 s of
# which 0.49 s were the full-grid block costs of every column
SCREEN_GRID = 50
SCREEN_KEEP = 2


def grid_size(n_grid: int, n_columns: int, p: int) -> int:
    """Candidate cuts per column within :data:`GRID_FLOPS` (at most ``n_grid``, at least
    :data:`MIN_GRID`)."""
    per_cut_pair = max(n_columns, 1) * (p ** 3 / 3 + p * p) / 2
    return int(min(n_grid, max(MIN_GRID, np.sqrt(GRID_FLOPS / per_cut_pair))))


# fingerprint of (x, Phi, y), min_rows, n_grid -> block costs (see _split_costs): one entry per
# column and fold, kept while a search grows the regions (16 columns x 5 folds thrashed 48 entries:
# every region count recomputed every table); a table of 200 cuts holds 0.3 MB
_COST_CACHE = BoundedCache(1024, maxbytes=128 * 2**20)
# fingerprint of (X, y), constant term -> the scaled rows (_scaled_rows) on which the block costs are
# computed: a search segments the same training rows for every number of regions
_ROWS_CACHE = BoundedCache(32, maxbytes=128 * 2**20)


def _split_costs(x, Phi, y, min_rows, n_grid, data_key=None):
    """Sorted ``x``, the candidate block boundaries, the least-squares cost of every admissible
    block between two of them, the cost of all rows in one block, whether the boundaries are a
    grid (fewer than the positions where ``x`` changes), the sorting order, the ridge and the
    normal equations accumulated at the boundaries (which :func:`_refine_cuts` reuses). They do
    not depend on the number of regions: a model search that grows the regions on the same rows
    reuses them (a small cache keyed by the data's hash;
    ``data_key``: a fingerprint of ``(Phi, y)`` already computed, with ``x`` a column of ``Phi``
    named in it, which spares hashing the rows again for every column)."""
    key = (data_key if data_key is not None else fingerprint(x, Phi, y), int(min_rows), int(n_grid))
    return _COST_CACHE.get_or_compute(key, lambda: _block_costs(x, Phi, y, min_rows, n_grid))


def _block_costs(x, Phi, y, min_rows, n_grid):
    """What :func:`_split_costs` returns, computed."""
    n, p = Phi.shape
    # blocks end only where x changes, so the order within ties moves nothing but the summation
    # order: numpy's quicksort (vectorised) sorted Silverbox's 20,000 rows in 0.17 ms, a stable
    # sort in 1.2 ms (60 sorts a search)
    order = np.argsort(x)
    xs = x[order]
    changes = np.flatnonzero(xs[1:] > xs[:-1]) + 1  # a cut at k splits rows [0, k) | [k, n)
    changes = changes[(changes >= min_rows) & (changes <= n - min_rows)]
    gridded = n > EXACT_ROWS and changes.size > n_grid
    if gridded:
        pick = np.unique(np.searchsorted(changes, np.quantile(changes, np.linspace(0, 1, n_grid))))
        changes = changes[np.clip(pick, 0, changes.size - 1)]
        changes = np.unique(changes)
    nodes = np.concatenate([[0], changes, [n]])  # block boundaries
    m = nodes.size
    # normal equations accumulated at the block boundaries only: the sums over the rows between
    # two consecutive boundaries (one product of the sorted rows each), then their running sums
    Pw = np.column_stack([Phi[order], y[order]])
    if 16 * m < n:
        C = np.cumsum(_block_grams(Pw, nodes.astype(np.int64)), axis=0)
    else:  # few rows between boundaries (small data): running sums over the rows
        C = np.concatenate([np.zeros((1, p + 1, p + 1)), np.cumsum(Pw[:, :, None] * Pw[:, None, :], axis=0)])[nodes]
    ridge = 1e-10 * float(np.trace(C[-1, :p, :p])) / p
    whole = float(_sse_pairs(C, np.array([0]), np.array([m - 1]), p, ridge)[0])
    ia, ib = np.triu_indices(m, k=1)
    ok = (nodes[ib] - nodes[ia]) >= min_rows
    cost = np.full((m, m), np.inf)
    cost[ia[ok], ib[ok]] = _sse_pairs(C, ia[ok], ib[ok], p, ridge)
    return xs, nodes, cost, whole, gridded, order, ridge, C


def optimal_split(x, Phi, y, n_regions, min_rows, n_grid=200, data_key=None, refine=True):
    """Exact least-squares split of the rows into ``n_regions`` intervals of ``x`` (module doc).

    Returns ``(sse, thresholds)``; ``sse`` is ``inf`` when no admissible split exists.
    ``data_key``: see :func:`_split_costs`. ``refine=False`` returns the grid's optimum as it is
    (on large data; the segmenter compares the columns by it and refines the winner's cuts).
    """
    Phi, y = np.asarray(Phi, dtype=float), np.asarray(y, dtype=float)
    xs, nodes, cost, whole, gridded, order, ridge, C = _split_costs(np.asarray(x, dtype=float), Phi, y, min_rows,
                                                                    n_grid, data_key)
    if n_regions == 1:
        return whole, []
    m = nodes.size
    # D[j] = best cost of covering rows [0, nodes[j]) with the blocks so far
    D = cost[0].copy()
    back = []
    for _ in range(n_regions - 1):
        total = D[:, None] + cost  # last block from node i to node j
        arg = np.argmin(total, axis=0)
        D = total[arg, np.arange(m)]
        back.append(arg)
    if not np.isfinite(D[-1]):
        return np.inf, None
    cuts = []
    j = m - 1
    for arg in reversed(back):
        j = int(arg[j])
        cuts.append(int(nodes[j]))
    cuts = cuts[::-1]
    sse = float(D[-1])
    if gridded and refine:  # the DP saw a grid: each cut moves to its exact best between the nodes around it
        sse, cuts = _refine_cuts(xs, order, Phi, y, nodes, C, cuts, min_rows, ridge)
    return sse, [0.5 * (xs[k - 1] + xs[k]) for k in cuts]


def _refine_cuts(xs, order, Phi, y, nodes, C, cuts, min_rows, ridge, rounds=3):
    """``(sse, cuts)`` of a grid solution with each cut moved to the best exact position between
    the grid nodes around it, one cut at a time with its neighbours held (coordinate descent on
    the exact residual sum of squares, a few rounds). The exact cost of every position between two
    nodes is one running sum of the rows there; the result is never worse than the grid's.
    ``C``: the normal equations accumulated at the grid ``nodes`` (:func:`_block_costs`), so that
    a block of rows costs the sums of its rows beyond the nearest nodes only (forming every block
    from its rows took 0.3 s of a Silverbox search: 20,000 rows a block, 40 refinements)."""
    n = xs.size
    p = Phi.shape[1]

    def rows(a, b):  # [Phi y] of the sorted rows [a, b)
        idx = order[a:b]
        return np.column_stack([Phi[idx], y[idx]])

    def gram(a, b):  # [Phi y]' [Phi y] over the sorted rows [a, b)
        i = int(np.searchsorted(nodes, a, side="left"))  # first node at or after a
        j = int(np.searchsorted(nodes, b, side="right")) - 1  # last node at or before b
        if i >= j:
            block = rows(a, b)
            return block.T @ block
        head, tail = rows(a, int(nodes[i])), rows(int(nodes[j]), b)
        return C[j] - C[i] + head.T @ head + tail.T @ tail

    cuts = [int(k) for k in cuts]
    pos = [int(np.searchsorted(nodes, k)) for k in cuts]  # each cut's grid node
    for _ in range(rounds):
        moved = False
        for j, k in enumerate(cuts):
            a = cuts[j - 1] if j > 0 else 0
            b = cuts[j + 1] if j + 1 < len(cuts) else n
            lo = max(int(nodes[max(pos[j] - 1, 0)]), a + min_rows)
            hi = min(int(nodes[min(pos[j] + 1, nodes.size - 1)]), b - min_rows)
            if hi <= lo:
                continue
            base = gram(a, lo)
            window = rows(lo, hi)
            total = base + window.T @ window + gram(hi, b)
            # the left block [a, c) for c = lo .. hi: base plus the window's rows before c
            left = np.concatenate([base[None], base + np.cumsum(window[:, :, None] * window[:, None, :], axis=0)])
            cand = np.arange(lo, hi + 1)
            ok = xs[cand - 1] < xs[np.minimum(cand, n - 1)]  # a cut between two distinct values
            if not np.any(ok):
                continue
            costs = np.full(cand.size, np.inf)
            costs[ok] = _sse_many(left[ok], p, ridge) + _sse_many(total - left[ok], p, ridge)
            best = int(np.argmin(costs))
            here = np.flatnonzero(cand == k)
            if cand[best] != k and (here.size == 0 or costs[best] < costs[here[0]]):
                cuts[j] = int(cand[best])
                moved = True
        if not moved:
            break
    edges = [0] + cuts + [n]
    refined = float(sum(_sse_many(gram(a, b)[None], p, ridge)[0] for a, b in zip(edges[:-1], edges[1:])))
    return refined, cuts  # each move lowered the cost of its two blocks: refined <= the grid's sse


@numba.njit(cache=True, nogil=True)
def _block_grams(Pw, nodes):  # pragma: no cover - compiled
    """``G[j] = B' B`` for the rows ``B = Pw[nodes[j-1]:nodes[j]]`` between two block boundaries
    (``G[0] = 0``), compiled: one product of each block's rows in numpy, 200 blocks a grid, took
    0.24 s of a Silverbox search's 117 tables."""
    m = nodes.size
    q = Pw.shape[1]
    G = np.zeros((m, q, q))
    for j in range(1, m):
        for k in range(nodes[j - 1], nodes[j]):
            for a in range(q):
                v = Pw[k, a]
                for b in range(a + 1):
                    G[j, a, b] += v * Pw[k, b]
        for a in range(q):
            for b in range(a):
                G[j, b, a] = G[j, a, b]
    return G


def _sse_many(S, p, ridge):
    """Residual sums of squares of least squares from stacked augmented Gram matrices
    ``S = [Phi y]' [Phi y]`` (k, p + 1, p + 1) of blocks of rows (a ``ridge`` on the diagonal)."""
    return _sse_pairs(S, None, None, p, ridge)


def _sse_pairs(C, ia, ib, p, ridge):
    """:func:`_sse_many` of the blocks ``C[ib] - C[ia]`` (``C``: running Gram matrices; ``ia``
    ``None``: of ``C`` itself), without stacking the differences: each residual sum of squares is
    the last pivot of the Cholesky factorisation of its augmented Gram matrix (compiled; the
    stacked differences and numpy's batched LU solve took 14 ms a table of 200 cuts at p = 9,
    this 2.6 ms). A block whose Gram matrix is not positive definite is solved by least squares
    (pseudo-inverse) instead."""
    pairs = ia is not None
    if not pairs:
        ia = ib = np.zeros(0, dtype=np.int64)
    ia = np.ascontiguousarray(ia, dtype=np.int64)
    ib = np.ascontiguousarray(ib, dtype=np.int64)
    out = _cholesky_sse(np.ascontiguousarray(C, dtype=float), ia, ib, pairs, int(p), float(ridge))
    bad = np.flatnonzero(np.isnan(out))
    if bad.size:
        S = C[ib[bad]] - C[ia[bad]] if pairs else C[bad]
        finite = np.all(np.isfinite(S), axis=(1, 2))  # rows with nan or inf keep a nan cost
        bad, S = bad[finite], S[finite]
        G = S[:, :p, :p] + ridge * np.eye(p)
        r = S[:, :p, p]
        theta = np.einsum("nij,nj->ni", np.linalg.pinv(G), r)
        out[bad] = np.maximum(S[:, p, p] - np.einsum("ni,ni->n", r, theta), 0.0)
    return out


@numba.njit(cache=True, nogil=True)
def _cholesky_sse(C, ia, ib, pairs, p, ridge):
    """The kernel of :func:`_sse_pairs`: NaN where a pivot of the first ``p`` is not positive."""
    k = ia.size if pairs else C.shape[0]
    q = p + 1
    out = np.empty(k)
    A = np.empty((q, q))
    for t in range(k):
        for i in range(q):
            for j in range(i + 1):
                A[i, j] = C[ib[t], i, j] - C[ia[t], i, j] if pairs else C[t, i, j]
        for i in range(p):
            A[i, i] += ridge
        out[t] = np.nan
        for j in range(q):
            s = A[j, j]
            for l in range(j):
                s -= A[j, l] * A[j, l]
            if j == p:  # the Schur complement of the Gram matrix: y'y - r' G^-1 r
                out[t] = max(s, 0.0)
                break
            if not s > 0.0:
                break
            d = np.sqrt(s)
            A[j, j] = d
            for i in range(j + 1, q):
                s2 = A[i, j]
                for l in range(j):
                    s2 -= A[i, l] * A[j, l]
                A[i, j] = s2 / d
    return out


def check_split_params(segmenter, owner: str) -> None:
    """The threshold split's settings (``column``, ``n_grid``, ``min_share``) of ``segmenter``."""
    from hwpts.identification.settings import is_count, is_number

    if segmenter.column is not None and not isinstance(segmenter.column, str):
        raise ParameterError(f"{owner}column must be a regressor column name such as 'y(k-1)' or None, "
                             f"got {segmenter.column!r}")
    n_grid = segmenter.n_grid  # a whole float (2.0) is read as its int, as before these checks
    if not (is_count(n_grid, 2) or (is_number(n_grid, 2.0) and float(n_grid).is_integer())):
        raise ParameterError(f"{owner}n_grid must be an int >= 2, got {n_grid!r}")
    if not (is_number(segmenter.min_share, 0.0, strict=True) and segmenter.min_share < 0.5):
        raise ParameterError(f"{owner}min_share must be a number in (0, 0.5) (each region's least share of "
                             f"the rows), got {segmenter.min_share!r}")


class ThresholdSegmenter(Segmenter):
    """Thresholds on one regressor column chosen by exact least squares (module doc).

    Parameters
    ----------
    column : str or None
        Threshold variable: a regressor name (``"y(k-1)"``, ``"u1(k-2)"``) or an input/output name
        (the output's name means its first lag); ``None`` (default) tries every regressor column
        and keeps the best.
    n_grid : int
        Candidate cuts on large data (more than 400 rows) when the column takes more values: this
        many quantiles (each cut then refined to its exact best position between the quantiles
        around it); fewer on wide regressors, within :data:`GRID_FLOPS` (:func:`grid_size`).
    min_share : float
        Smallest share of the training rows in each region (and always more rows than parameters).
    """

    name = "threshold"
    returns_partition = True
    uses_n_regions = True
    restricts_columns = True

    def __init__(self, *, column: str | None = None, n_grid: int = 200, min_share: float = 0.03):
        self.column = column
        self.n_grid = n_grid
        self.min_share = min_share

    def check_params(self) -> None:
        """``column``, ``n_grid`` and ``min_share`` (see :meth:`Segmenter.check_params`)."""
        check_split_params(self, "threshold: ")

    def segment(self, X, y, n_regions, structure, rng, columns=None) -> SegmentationResult:
        """The exact least-squares thresholds on the chosen column (or the best column), as a fixed
        partition. ``columns``: the regressor columns a threshold may use (a PWARX's
        ``partition_columns``); default all."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        self._check_regions(n_regions, X.shape[0])
        if not 0 < self.min_share < 1 / max(n_regions, 2):
            most = int(np.ceil(1 / self.min_share)) - 1 if 0 < self.min_share < 1 else 0
            raise ParameterError(f"threshold: {n_regions} regions cannot each hold min_share={self.min_share} of "
                                 f"the rows: at most {most} regions at that share (min_share must be in "
                                 f"(0, 1/n_regions))")
        n, nf = X.shape
        allowed = range(nf) if columns is None else sorted({int(c) for c in columns})
        if self.column is None:
            columns = [c for c in allowed if np.ptp(X[:, c]) > 0]
        else:
            columns = [structure.column_index(self.column)]
            if columns[0] not in allowed:
                raise ParameterError(
                    f"threshold: column {self.column!r} is not among the partition columns "
                    f"{[structure.feature_names[c] for c in allowed]}")
        if n_regions == 1 or not columns:
            name = self.column if self.column is not None else None
            return SegmentationResult(np.zeros(n, dtype=np.int64), 1, RegionPartition.single(nf),
                                      refine=False, info={"column": name, "thresholds": []})
        # the scaled rows of these (X, y), and the key of their block costs: one hash of the rows
        # for every column and every number of regions (hashing costs as much as a split, and the
        # basis an SVD of all rows: 0.3 s of a Silverbox search's 42 segmentations recomputed it for
        # each number of regions of the same training rows)
        rows = (fingerprint(X, y), bool(structure.constant))
        Phi, y, y_scale = _ROWS_CACHE.get_or_compute(rows, lambda: _scaled_rows(X, y, structure))
        p = nf + int(structure.constant)  # parameters of a local model (Phi may span fewer columns)
        min_rows = max(int(np.ceil(self.min_share * n)), p + 1)
        n_grid = grid_size(int(self.n_grid), len(columns), p)
        best = (np.inf, None, None)
        if n > EXACT_ROWS and n_grid > SCREEN_GRID and len(columns) > SCREEN_KEEP:
            # the columns screened on a coarse grid; the best SCREEN_KEEP go on to the full grid
            coarse = [optimal_split(X[:, c], Phi, y, n_regions, min_rows, SCREEN_GRID, data_key=(rows, c),
                                    refine=False)[0] for c in columns]
            columns = [columns[i] for i in np.argsort(coarse, kind="stable")[:SCREEN_KEEP]]
        for c in columns:  # the columns compared by their grid optimum; the winner's cuts refined
            sse, thresholds = optimal_split(X[:, c], Phi, y, n_regions, min_rows, n_grid,
                                            data_key=(rows, c), refine=len(columns) == 1)
            if sse < best[0]:
                best = (sse, c, thresholds)
        sse, c, thresholds = best
        if c is not None and len(columns) > 1:
            sse, thresholds = optimal_split(X[:, c], Phi, y, n_regions, min_rows, n_grid,
                                            data_key=(rows, c))
        if c is None:
            raise IdentificationError(
                f"threshold: no split of {n} rows into {n_regions} regions of >= {min_rows} rows each "
                f"on {'any column' if self.column is None else repr(self.column)}"
            )
        partition = threshold_partition(c, thresholds, nf)
        labels = partition.predict(X)
        return SegmentationResult(labels, n_regions, partition, refine=False,
                                  info={"column": structure.feature_names[c],
                                        "thresholds": [float(t) for t in thresholds],
                                        "sse": float(sse) * y_scale ** 2})


def _scaled_rows(X, y, structure):
    """``(Phi, y, y_scale)``: the rows in a basis in which the block costs are accurate whatever the
    data's units and the collinearity of its lags. The regressors ``[X 1]`` (centred and scaled
    columns) are replaced by an orthonormal basis of the space they span (times ``sqrt(n)``), and
    the output by its residual from the least squares on all rows, divided by that residual's
    standard deviation ``y_scale``. Both are exact for every block: a block's regressors span the
    same functions of its rows, and the removed fit lies in that span, so a block's residual sum
    of squares is the raw one over ``y_scale ** 2``. On the raw rows the Cholesky pivot
    ``y'y - r'G^-1 r`` cancelled: EMPS's lagged positions (na = 4) have a Gram matrix conditioned
    around 1e12, and the block costs came out 10-60x the true residual sums, with more regions
    costing *more* (a split into 3 blocks costing more than one of its 2-block splits); a ridge of
    1e-10 of the Gram matrix's mean diagonal, which an offset of 1e6 or a scale of 1e-7 in the
    data dwarfs or swamps, moved a two-region system's split to the wrong column (70 % training
    fit instead of 100 %)."""
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    n = X.shape[0]
    sd = X.std(axis=0)
    sd[~(sd > 0)] = 1.0
    Phi = structure.extend((X - X.mean(axis=0)) / sd) if structure.constant else X / sd
    U, sv, _ = np.linalg.svd(Phi, full_matrices=False)
    U = U[:, sv > sv[0] * max(Phi.shape) * np.finfo(float).eps] if sv.size and sv[0] > 0 else U[:, :0]
    r = y - U @ (U.T @ y)
    y_scale = float(np.sqrt(np.mean(r ** 2)))
    if not y_scale > 0:  # an exact fit on all rows: every block's cost is zero
        y_scale = 1.0
    return U * np.sqrt(n), r / y_scale, y_scale
