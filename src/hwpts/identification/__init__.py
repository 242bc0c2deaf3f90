"""PWARX identification (paper section IV): works on anyone's input/output data.

This package never imports :mod:`hwpts.plant`.

- :mod:`.regressors`: regression vectors (eqs. 6-7);
- :mod:`.segmentation`: the methods, one per file, chosen by name;
- :mod:`.partition`: polyhedral partitions (eq. 9) and the region classifier;
- :mod:`.local_models`: least squares per region (eq. 17);
- :mod:`.pwarx`: the estimator (one model); :mod:`.selection`: the model search wrapping it
  (:class:`PWARXSearch`) and time-series splitters; :mod:`.simulation`: the switching-rule free run;
- :mod:`.statespace`: state-space form of each mode (eq. 7); :mod:`.metrics`: fit %, accuracy.
"""

from hwpts.identification.local_models import RegionWarning
from hwpts.identification.metrics import fit_percent, parameter_error, region_accuracy, rmse
from hwpts.identification.partition import Hyperplane, RegionPartition
from hwpts.identification.pwarx import PWARX, FreeRunDivergedWarning
from hwpts.identification.regressors import RegressorStructure
from hwpts.identification.segmentation import SEGMENTATION_METHODS, make_segmenter
from hwpts.identification.selection import BlockedSplit, HoldoutSplit, PWARXSearch
from hwpts.identification.simulation import SimulationResult

__all__ = [
    "PWARX", "PWARXSearch", "BlockedSplit", "HoldoutSplit", "RegressorStructure", "RegionPartition", "Hyperplane", "SimulationResult",
    "SEGMENTATION_METHODS", "make_segmenter", "RegionWarning", "FreeRunDivergedWarning",
    "fit_percent", "rmse", "region_accuracy", "parameter_error",
]
