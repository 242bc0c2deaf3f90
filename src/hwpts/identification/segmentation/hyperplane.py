"""``hyperplane``: a partition given by the user as hyperplanes (the paper's fracture line, eqs. 15-16).

Each hyperplane is ``a_1 x_{c1} + a_2 x_{c2} + ... + c >= 0`` on named regressor columns (or input
names, meaning the input's most recent sample in the regressor); the ordered list is a decision
list (see :func:`hwpts.identification.partition.hyperplane_partition`): ``m`` hyperplanes give
``m + 1`` convex polyhedral regions (eq. 9).

The paper's construction (section V.B): a space line through two operating points
``(h_i, omega_p, omega_mA)`` on the fracture of the steady-state surface (eq. 15), projected onto
the input plane ``(h_i, omega_p)`` (eq. 16): ``omega_p = -486.41 h_i + 1755.2``. See
:func:`space_line`, :func:`project_space_line` and :func:`fracture_hyperplane`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hwpts.errors import IdentificationError, ParameterError
from hwpts.identification.partition import Hyperplane, hyperplane_partition
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter

__all__ = ["HyperplaneSegmenter", "space_line", "project_space_line", "fracture_hyperplane",
           "PAPER_POINTS", "PAPER_SPACE_LINE"]

#: the two operating points (h_i [V], omega_p [r/min], omega_mA [r/min]) of section V.B
PAPER_POINTS = ((2.95, 328.0, 489.5), (1.8, 904.0, 1566.0))
#: the space line as printed in eq. 15: origin (t = 0) and direction (per unit t)
PAPER_SPACE_LINE = ((1.75, 904.0, 1572.0), (1.25, -608.0, -1149.0))


def space_line(p1: Sequence[float], p2: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """Space line through two operating points (eq. 15): ``p(t) = origin + t * direction``.

    The origin is ``p2`` and the direction ``p1 - p2`` (``t = 0`` at ``p2``, ``t = 1`` at ``p1``).
    """
    a = np.asarray(p1, dtype=float)
    b = np.asarray(p2, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or a.size < 2:
        raise ParameterError(f"operating points must be vectors of equal length >= 2; got {a}, {b}")
    if np.allclose(a[:2], b[:2]):
        raise ParameterError("the two operating points coincide in the input plane: no line")
    return b, a - b


def project_space_line(origin, direction) -> tuple[float, float]:
    """Projection of a space line on the plane of its first two coordinates (eq. 16).

    Returns ``(slope, intercept)`` of ``x2 = slope * x1 + intercept`` (for the paper:
    ``omega_p = slope * h_i + intercept``).
    """
    o = np.asarray(origin, dtype=float)
    d = np.asarray(direction, dtype=float)
    if d[0] == 0:
        raise ParameterError("the projected line is vertical (x1 constant); use a threshold hyperplane")
    slope = d[1] / d[0]
    return float(slope), float(o[1] - slope * o[0])


def fracture_hyperplane(slope: float, intercept: float, columns: Sequence[str]) -> Hyperplane:
    """Half-space above the line ``x2 = slope*x1 + intercept``: ``-slope*x1 + x2 - intercept >= 0``."""
    return Hyperplane([-slope, 1.0], -intercept, columns)


class HyperplaneSegmenter(Segmenter):
    """Partition by given hyperplanes (strings ``"a,b,c[@col1,col2]"`` or :class:`Hyperplane`)."""

    name = "hyperplane"
    returns_partition = True
    uses_n_regions = False

    def __init__(self, *, hyperplanes=()):
        self.hyperplanes = hyperplanes

    def parsed(self) -> list[Hyperplane]:
        """The hyperplanes as :class:`Hyperplane` objects (strings parsed)."""
        if isinstance(self.hyperplanes, (str, bytes, Hyperplane)) or not hasattr(self.hyperplanes, "__iter__"):
            raise ParameterError(f"hyperplane: hyperplanes must be a list of 'a,b,c' texts or Hyperplane objects "
                                 f"(one per boundary), got {self.hyperplanes!r}")
        return [hp if isinstance(hp, Hyperplane) else Hyperplane.parse(hp) for hp in self.hyperplanes]

    def check_params(self) -> None:
        """``hyperplanes``: a list, each one parsed (see :meth:`Segmenter.check_params`)."""
        self.parsed()

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """The decision list of the user's hyperplanes as a fixed partition (m hyperplanes, m + 1 regions)."""
        X, y, rng = self._check_rows(X, y, rng)
        hps = self.parsed()
        if not hps:
            raise ParameterError(
                "segmentation 'hyperplane' needs at least one hyperplane: hyperplanes=[\"a,b,c\"] meaning "
                "a*x1 + b*x2 + c >= 0 (on the command line --hyperplane \"a,b,c\")"
            )
        partition = hyperplane_partition(hps, structure)
        labels = partition.predict(X)
        counts = np.bincount(labels, minlength=partition.n_regions)
        empty = [i + 1 for i, c in enumerate(counts) if c == 0]
        if empty:
            raise IdentificationError(
                f"the hyperplanes {[repr(h) for h in hps]} leave region(s) {empty} of "
                f"{partition.n_regions} empty: no training sample falls there; move or drop a hyperplane"
            )
        return SegmentationResult(labels, partition.n_regions, partition, refine=False,
                                  info={"hyperplanes": [h.to_dict() for h in hps]})
