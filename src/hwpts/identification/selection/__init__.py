"""Model selection: the one search (:class:`PWARXSearch`) and time-series splitters.

``PWARXSearch(PWARX(...))`` chooses the number of regions, the segmentation method and, when asked,
the orders, by the cross-validated free-run fit on the training data only. ``hwpts identify`` runs
it by default; the paper pipeline's ``best`` runs it on a grid with a held-out tail.
"""

from hwpts.identification.selection.search import DEFAULT_METHODS, ORDER_GRID, PWARXSearch, expand_grid
from hwpts.identification.selection.splitters import BlockedSplit, HoldoutSplit, TimeSeriesSplit, breaks_of

__all__ = ["PWARXSearch", "expand_grid", "BlockedSplit", "HoldoutSplit", "TimeSeriesSplit", "breaks_of",
           "DEFAULT_METHODS", "ORDER_GRID"]
