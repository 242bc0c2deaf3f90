"""``threshold``: regions split by thresholds on one regressor column (SETAR / TARX models).

The switching of many real systems depends on one signal crossing a level: a position where a
head touches a surface, a pressure where a valve opens, a level where a tank overflows. Such a
PWARX model is a *threshold* ARX model (Tong's SETAR/TARX, Tong 1990; Hansen 2000): with the
threshold variable ``x_c`` (a regressor column, default ``y(k-1)``) and ordered thresholds
``t_1 < ... < t_{s-1}``, region ``i`` is ``{x : t_{i-1} < x_c <= t_i}`` (a polyhedron, eq. 9).

The thresholds are estimated by conditional least squares: for every candidate split (quantiles of
``x_c`` on a grid, each region holding at least ``min_share`` of the samples and more rows than
parameters) the local least squares (eq. 17) are solved and the split with the smallest total
residual sum of squares wins. Sorting the rows by ``x_c`` and accumulating the normal equations
makes every split cost one small solve per region, so ``s = 2`` and ``s = 3`` are exhaustive
searches. The result is deterministic (no random restarts) and the partition is fixed (no boundary
refinement): few boundary parameters, low variance, which suits free-run simulation.
"""

from __future__ import annotations

import itertools

import numpy as np

from hwpts.errors import IdentificationError, ParameterError
from hwpts.identification.partition import RegionPartition
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter

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
    return RegionPartition(H, g, kind="thresholds")


def _sse(G, b, yy, ridge):
    """Residual sum of squares of least squares from the normal equations (G, b, y'y)."""
    p = G.shape[0]
    try:
        theta = np.linalg.solve(G + ridge * np.eye(p), b)
    except np.linalg.LinAlgError:
        return np.inf
    return float(yy - b @ theta)


class ThresholdSegmenter(Segmenter):
    """Thresholds on one regressor column chosen by least squares (module doc).

    Parameters
    ----------
    column : str
        Threshold variable: a regressor name (``"y(k-1)"``, ``"u1(k-2)"``) or an input/output name.
    n_grid : int
        Candidate thresholds: this many quantiles of the column (between ``min_share`` and
        ``1 - min_share``).
    min_share : float
        Smallest share of the training rows in each region.
    """

    name = "threshold"
    uses_n_regions = True

    def __init__(self, column: str = "y(k-1)", n_grid: int = 60, min_share: float = 0.05):
        self.column = column
        self.n_grid = n_grid
        self.min_share = min_share

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        self._check_regions(n_regions, X.shape[0])
        if n_regions > 3:
            raise ParameterError(f"threshold segmentation searches 1 to 3 regions exhaustively, got {n_regions}")
        if not 0 < self.min_share < 1 / max(n_regions, 2) or int(self.n_grid) < 2:
            raise ParameterError(f"threshold: min_share must be in (0, 1/n_regions) and n_grid >= 2; "
                                 f"got {self.min_share}, {self.n_grid}")
        c = structure.column_index(self.column)
        n, nf = X.shape
        x = X[:, c]
        if n_regions == 1:
            return SegmentationResult(np.zeros(n, dtype=np.int64), 1, RegionPartition.single(nf),
                                      refine=False, info={"column": self.column, "thresholds": []})
        order = np.argsort(x, kind="stable")
        xs = x[order]
        Phi = structure.extend(X)[order]
        ys = y[order]
        p = Phi.shape[1]
        # cumulative normal equations over the sorted rows: block [a, b) = C[b] - C[a]
        CG = np.concatenate([np.zeros((1, p, p)), np.cumsum(Phi[:, :, None] * Phi[:, None, :], axis=0)])
        Cb = np.concatenate([np.zeros((1, p)), np.cumsum(Phi * ys[:, None], axis=0)])
        Cy = np.concatenate([[0.0], np.cumsum(ys**2)])
        ridge = 1e-10 * float(np.trace(CG[-1])) / p
        min_rows = max(int(np.ceil(self.min_share * n)), p + 1)
        qs = np.linspace(self.min_share, 1 - self.min_share, int(self.n_grid))
        # candidate cut positions: split between sorted rows k-1 and k, only where x changes
        cuts = sorted({int(np.searchsorted(xs, v, side="right")) for v in np.quantile(xs, qs)})
        cuts = [k for k in cuts if min_rows <= k <= n - min_rows and xs[k - 1] < xs[k]]
        if not cuts:
            raise IdentificationError(f"threshold: column {self.column!r} has too few distinct values to split")

        def block(a, b):
            return _sse(CG[b] - CG[a], Cb[b] - Cb[a], Cy[b] - Cy[a], ridge)

        best, best_cuts = np.inf, None
        for combo in itertools.combinations(cuts, n_regions - 1):
            bounds = (0, *combo, n)
            if any(bounds[i + 1] - bounds[i] < min_rows for i in range(n_regions)):
                continue
            total = sum(block(bounds[i], bounds[i + 1]) for i in range(n_regions))
            if total < best:
                best, best_cuts = total, combo
        if best_cuts is None:
            raise IdentificationError(
                f"threshold: no split of {n} rows into {n_regions} regions of >= {min_rows} rows each"
            )
        thresholds = [0.5 * (xs[k - 1] + xs[k]) for k in best_cuts]
        partition = threshold_partition(c, thresholds, nf)
        labels = partition.predict(X)
        return SegmentationResult(labels, n_regions, partition, refine=False,
                                  info={"column": self.column, "thresholds": [float(t) for t in thresholds],
                                        "sse": float(best)})
