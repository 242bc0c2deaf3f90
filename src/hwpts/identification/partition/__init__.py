"""Partitions of the regressor space (paper eq. 9).

- :mod:`.polyhedra`: :class:`RegionPartition` (polyhedra ``{x : H_i x + g_i <= 0}``), hyperplanes
  and the multicategory linear classifier that turns labels into polyhedra;
- :mod:`.learner`: :class:`PartitionLearner`, the classifier plus boundary refinement used for
  learned segmentations, with its constants as parameters.
"""

from hwpts.identification.partition.learner import TRIM, PartitionLearner, drop_empty_regions
from hwpts.identification.partition.polyhedra import (
    Hyperplane,
    RegionPartition,
    fit_linear_partition,
    hyperplane_partition,
    scores_to_partition,
)

__all__ = ["RegionPartition", "Hyperplane", "hyperplane_partition", "fit_linear_partition",
           "scores_to_partition", "PartitionLearner", "drop_empty_regions", "TRIM"]
