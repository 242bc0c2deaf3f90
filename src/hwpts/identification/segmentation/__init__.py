"""Segmentation methods, one per file, chosen by name from :data:`SEGMENTATION_METHODS`.

The registry's keys are the names the CLI accepts (``hwpts identify --segmentation NAME``):

- ``average``: one region (plain ARX, the paper's baseline);
- ``zscore``: two regions by the z-score of the observations (paper section V.B);
- ``kmeans``: k-means of the scaled regressors (paper section V.B);
- ``hyperplane``: user-given hyperplanes, e.g. the paper's fracture line (eqs. 15-16);
- ``clustering``: Ferrari-Trecate et al. (2003) clustering of local parameter vectors;
- ``alternating``: alternating assignment / least squares with a separability term (k-LinReg, PARC);
- ``threshold``: thresholds on one regressor column, e.g. ``y(k-1)``, by least squares (SETAR/TARX);
- ``threshold-alternating``: that threshold split as the start of the alternation, the partition
  then learned (oblique boundaries from contiguous modes);
- ``hinging``: ``n_regions - 1`` hinging hyperplanes of a continuous PWA map (Breiman 1993), the
  regions their sides (boundaries where the pieces meet: saturations, dead zones);
- ``switched``: ``n_regions`` distinct local models (switched regression), then the regions each covers
  (modes that share parameters on disjoint regions);

Choosing the method and the number of regions from the data is model selection, not segmentation:
:class:`hwpts.identification.PWARXSearch` (``hwpts identify`` without ``--segmentation``).
"""

from __future__ import annotations

from hwpts.errors import ParameterError
from hwpts.identification.segmentation.alternating import AlternatingSegmenter
from hwpts.identification.segmentation.average import AverageSegmenter
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter, clear_caches
from hwpts.identification.segmentation.clustering import ClusteringSegmenter
from hwpts.identification.segmentation.hinging import HingingSegmenter
from hwpts.identification.segmentation.hyperplane import HyperplaneSegmenter
from hwpts.identification.segmentation.kmeans import KMeansSegmenter
from hwpts.identification.segmentation.switched import SwitchedSegmenter
from hwpts.identification.segmentation.threshold import ThresholdSegmenter
from hwpts.identification.segmentation.threshold_alternating import ThresholdAlternatingSegmenter
from hwpts.identification.segmentation.zscore import ZScoreSegmenter

SEGMENTATION_METHODS: dict[str, type[Segmenter]] = {
    "average": AverageSegmenter,
    "zscore": ZScoreSegmenter,
    "kmeans": KMeansSegmenter,
    "hyperplane": HyperplaneSegmenter,
    "clustering": ClusteringSegmenter,
    "alternating": AlternatingSegmenter,
    "threshold": ThresholdSegmenter,
    "threshold-alternating": ThresholdAlternatingSegmenter,
    "switched": SwitchedSegmenter,
    "hinging": HingingSegmenter,
}

__all__ = ["SEGMENTATION_METHODS", "make_segmenter", "Segmenter", "SegmentationResult", "clear_caches",
           "AlternatingSegmenter", "AverageSegmenter", "ClusteringSegmenter", "HingingSegmenter", "HyperplaneSegmenter",
           "KMeansSegmenter", "SwitchedSegmenter", "ThresholdAlternatingSegmenter", "ThresholdSegmenter",
           "ZScoreSegmenter"]


def make_segmenter(name: str, **params) -> Segmenter:
    """The segmenter registered as ``name``, built with ``params``; unknown names list valid ones."""
    if isinstance(name, Segmenter):
        return name
    try:
        cls = SEGMENTATION_METHODS[name]
    except (KeyError, TypeError):
        raise ParameterError(
            f"unknown segmentation {name!r}; valid methods are {sorted(SEGMENTATION_METHODS)}"
        ) from None
    try:
        return cls(**params)
    except TypeError as error:
        raise ParameterError(f"segmentation {name!r}: bad parameters {params} ({error})") from None
