"""``kmeans``: k clusters of the scaled regressors (paper section V.B, k-means [50]).

Each standardised regression vector ``x_k`` (eq. 7) goes to the cluster with the nearest mean;
the clusters are the region labels. Fast and simple; it ignores the dynamics, so the local
models can be poor or unstable (BENCHMARKS.md: a naive k-means PWARX diverges on the actuator data).
"""

from __future__ import annotations

import numpy as np

from hwpts.identification.segmentation.base import SegmentationResult, Segmenter, standardize


class KMeansSegmenter(Segmenter):
    name = "kmeans"

    def __init__(self, include_output: bool = False, n_init: int = 10):
        self.include_output = include_output
        self.n_init = n_init

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        from sklearn.cluster import KMeans

        self._check_regions(n_regions, X.shape[0])
        Z = standardize(np.column_stack([X, y]) if self.include_output else X)
        km = KMeans(n_clusters=n_regions, n_init=self.n_init,
                    random_state=int(rng.integers(2**31 - 1)))
        labels = km.fit_predict(Z).astype(np.int64)
        return SegmentationResult(labels, n_regions, refine=False, info={"inertia": float(km.inertia_)})
