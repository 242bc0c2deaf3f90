"""``zscore``: two partitions by the z-score of the observations (paper section V.B).

The z-score of an observation is ``z_k = (y_k - mean(y)) / std(y)``. Region 1 holds the samples with
``z_k < threshold``, region 2 those with ``z_k >= threshold`` (default threshold 0: below / above
the mean level). A two-sided split ``|z_k| > threshold`` would not be a convex polyhedron of the
regressor set (eq. 9), so the one-sided split is used; the regions seen by the switching rule are
then the best linear separation of these labels over the regressors.
"""

from __future__ import annotations

import numpy as np

from hwpts.errors import IdentificationError, ParameterError
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter


class ZScoreSegmenter(Segmenter):
    """``zscore``: two regions split by the z-score of the observed output at ``threshold`` (the paper's alternative segmentation).

    Parameters
    ----------
    threshold : float
        The split ``z >= threshold`` (default 0: above and below the mean).
    """
    name = "zscore"
    uses_n_regions = False
    fixed_regions = 2

    def __init__(self, *, threshold: float = 0.0):
        self.threshold = threshold

    def check_params(self) -> None:
        """``threshold`` (see :meth:`Segmenter.check_params`)."""
        from hwpts.identification.settings import is_number

        if not is_number(self.threshold, -np.inf):
            raise ParameterError(f"zscore: threshold must be a finite number (a z-score of the output), "
                                 f"got {self.threshold!r}")

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """Two regions: rows whose output's z-score is at least ``threshold``, and the rest."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        sd = float(np.std(y))
        if sd == 0:
            raise IdentificationError("zscore segmentation needs a non-constant output")
        z = (y - y.mean()) / sd
        labels = (z >= self.threshold).astype(np.int64)
        if labels.min() == labels.max():
            raise IdentificationError(
                f"zscore threshold {self.threshold} leaves a region empty; choose a threshold "
                f"between {z.min():.3g} and {z.max():.3g}"
            )
        return SegmentationResult(labels, 2, info={"threshold": float(self.threshold)})
