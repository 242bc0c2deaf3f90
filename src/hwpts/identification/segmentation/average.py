"""``average``: every sample in one region, i.e. a single affine ARX model (the paper's baseline)."""

from __future__ import annotations

import numpy as np

from hwpts.identification.segmentation.base import SegmentationResult, Segmenter


class AverageSegmenter(Segmenter):
    """One region for all data (paper section V.B "average" method): plain least-squares ARX."""

    name = "average"
    returns_partition = True
    uses_n_regions = False
    fixed_regions = 1

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """One region holding every row: a single ARX model."""
        X, y, rng = self._check_rows(X, y, rng)
        from hwpts.identification.partition import RegionPartition

        return SegmentationResult(np.zeros(X.shape[0], dtype=np.int64), 1,
                                  RegionPartition.single(X.shape[1]), refine=False)
