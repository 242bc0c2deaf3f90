"""``kmeans``: k clusters of the scaled regressors (paper section V.B, k-means [50]).

Each standardised regression vector ``x_k`` (eq. 7) goes to the cluster with the nearest mean;
the clusters are the region labels. Fast and simple; it ignores the dynamics, so the local
models can be poor or unstable (a naive k-means PWARX diverges on the hydraulic actuator data).
"""

from __future__ import annotations

import numpy as np

from hwpts.identification.segmentation.base import SegmentationResult, Segmenter, kmeans_labels, standardize
from hwpts.identification.settings import check_bool, check_count


class KMeansSegmenter(Segmenter):
    """``kmeans``: k-means on the standardised regressors (optionally with the output); the naive baseline.

    Parameters
    ----------
    include_output : bool
        Cluster ``[x_k, y_k]`` instead of ``x_k``.
    n_init : int
        k-means restarts.
    """
    name = "kmeans"
    learns_partition = True

    def __init__(self, *, include_output: bool = False, n_init: int = 10):
        self.include_output = include_output
        self.n_init = n_init

    def check_params(self) -> None:
        """``n_init`` and ``include_output`` (see :meth:`Segmenter.check_params`)."""
        check_count(self.n_init, "n_init", 1, "kmeans: ")
        check_bool(self.include_output, "include_output", "kmeans: ")

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """Labels from k-means on the standardised regressors."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        self._check_regions(n_regions, X.shape[0])
        Z = standardize(np.column_stack([X, y]) if self.include_output else X)
        labels = kmeans_labels(Z, n_regions, rng, self.n_init)
        return SegmentationResult(labels, n_regions, refine=False)
