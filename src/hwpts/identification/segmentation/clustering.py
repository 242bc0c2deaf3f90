"""``clustering``: the clustering procedure of Ferrari-Trecate, Muselli, Liberati & Morari,
"A clustering technique for the identification of piecewise affine systems", Automatica 39(2), 2003.

1. For every sample ``k``, a *local dataset*: its ``c`` nearest neighbours in the (standardised)
   regressor space, itself included.
2. Local least squares on each local dataset gives ``theta_k`` and a residual variance ``V_k``.
3. Feature vectors ``xi_k = [theta_k, m_k]`` with ``m_k`` the mean regressor of the local dataset.
   Because ``m_k`` is part of the feature, modes with *equal* parameters on *disjoint* regions stay
   apart (synthetic system 1, :mod:`hwpts.identification.synthetic`), which clustering on parameters alone cannot do.
4. Weighted k-means on the features; the weight of ``xi_k`` is its confidence ``1 / V_k``, so
   local datasets that straddle a boundary ("mixed", large residual) hardly move the centres.
5. Sample ``k`` gets the cluster of its feature vector.

The estimator then fits the region classifier (eq. 9) and the local models (eq. 17). Steps 1-4 are
vectorised (batched normal equations), so the method scales to 10^5 samples.
"""

from __future__ import annotations

import numpy as np

from hwpts.identification.segmentation.base import (
    BoundedCache,
    SegmentationResult,
    Segmenter,
    fingerprint,
    kmeans_labels,
    standardize,
)
from hwpts.identification.threads import single_threaded
from hwpts.identification.settings import check_count


_FEATURE_CACHE = BoundedCache(24)  # fingerprint of (X, y), n_neighbors -> local features (see local_features)


def local_features(X, y, n_neighbors: int):
    """Local parameter vectors, mean regressors and residual variances (steps 1-3).

    They do not depend on the number of regions: a model search that grows the regions on the same
    rows (the alternating method starts from this clustering) reuses them from a small cache keyed
    by the rows' hash (the nearest-neighbour search is most of the clustering's cost)."""
    key = (fingerprint(X, y), int(n_neighbors))
    hit = _FEATURE_CACHE.get_or_compute(key, lambda: _local_features(X, y, n_neighbors))
    return tuple(a.copy() if isinstance(a, np.ndarray) else a for a in hit)


def _local_features(X, y, n_neighbors: int):
    from sklearn.neighbors import NearestNeighbors

    Z = standardize(X)
    ys = (y - y.mean()) / (y.std() or 1.0)
    n, nf = Z.shape
    p = nf + 1
    c = int(min(max(n_neighbors, p + 1), n))
    with single_threaded("openmp"):  # see base.kmeans_labels
        idx = NearestNeighbors(n_neighbors=c).fit(Z).kneighbors(Z, return_distance=False)
    P = np.concatenate([Z[idx], np.ones((n, c, 1))], axis=2)  # (n, c, p)
    Y = ys[idx]
    G = np.einsum("nci,ncj->nij", P, P)
    G += 1e-9 * np.trace(G, axis1=1, axis2=2)[:, None, None] * np.eye(p)
    r = np.einsum("nci,nc->ni", P, Y)
    theta = np.linalg.solve(G, r[..., None])[..., 0]
    res = Y - np.einsum("nci,ni->nc", P, theta)
    V = (res**2).sum(axis=1) / max(c - p, 1)
    m = Z[idx].mean(axis=1)
    return theta, m, V, c


class ClusteringSegmenter(Segmenter):
    """Ferrari-Trecate et al. (2003) clustering of local parameter vectors (see module doc).

    Parameters
    ----------
    n_neighbors : int or None
        Size ``c`` of each local dataset; default ``max(2 p, p + 3)`` for ``p`` parameters per mode.
    n_init : int
        k-means restarts.
    """

    name = "clustering"
    learns_partition = True

    def __init__(self, *, n_neighbors: int | None = None, n_init: int = 10):
        self.n_neighbors = n_neighbors
        self.n_init = n_init

    def check_params(self) -> None:
        """``n_neighbors`` and ``n_init`` (see :meth:`Segmenter.check_params`)."""
        if self.n_neighbors is not None:
            check_count(self.n_neighbors, "n_neighbors", 2, "clustering: ")
        check_count(self.n_init, "n_init", 1, "clustering: ")

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """Labels from clustering the local-model features of Ferrari-Trecate et al. (see the module docstring)."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        self._check_regions(n_regions, X.shape[0])
        p = X.shape[1] + 1
        c = self.n_neighbors if self.n_neighbors is not None else max(2 * p, p + 3)
        theta, m, V, c = local_features(X, y, c)
        if n_regions == 1:
            return SegmentationResult(np.zeros(X.shape[0], dtype=np.int64), 1, info={"n_neighbors": c})
        scale_v = np.median(V) + 1e-12 * (np.max(V) + 1e-300)
        w = 1.0 / (V + 0.01 * scale_v + 1e-300)
        w = w / w.sum()
        F = np.hstack([theta, m])
        mu = np.average(F, axis=0, weights=w)
        sd = np.sqrt(np.average((F - mu) ** 2, axis=0, weights=w))
        sd[sd == 0] = 1.0
        F = (F - mu) / sd
        F[:, :p] /= np.sqrt(p)
        F[:, p:] /= np.sqrt(max(X.shape[1], 1))
        labels = kmeans_labels(F, n_regions, rng, self.n_init, sample_weight=w * len(w))
        return SegmentationResult(labels, n_regions, info={"n_neighbors": int(c)})
