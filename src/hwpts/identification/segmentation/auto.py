"""``auto``: choose the segmentation method and the number of regions on the training data only.

Every candidate (``average`` with one region; each learned method with 2 .. ``max_regions``
regions) is scored by its *free-run* fit on held-out training data, simulated from measured initial
conditions. Two schemes:

- ``scheme="blocked"`` (default): blocked cross-validation for time series (Bergmeir & Benitez
  2012), as :func:`hwpts.identification.selection.select_model`: the record is cut into
  ``n_folds`` contiguous blocks, each simulated in free run by the candidate fitted on the others;
  the score is the mean over blocks. Every regime of the record is validated.
- ``scheme="tail"``: fitted on the head of the record and simulated on the last ``holdout`` share
  (one block, cheaper; only the end of the record is validated).

A candidate whose free run diverges on any block is rejected (a naive k-means PWARX diverges on
the actuator data); among the rest, the best score wins, and a candidate within ``tolerance``
percentage points of it is preferred when it has fewer regions or only stable modes (state-space
poles inside the unit circle, eq. 7). The winner is then scored once more with the
simulation-error polish (``polish=True``, :mod:`hwpts.identification.polish`) on the same blocks and
polished if that raises its held-out fit by more than ``tolerance`` (the rule between candidates:
stability decides only within ``tolerance``; ``try_polish=False`` skips this). The winner is refitted on all the training data.
``segmentation_params`` given to ``auto`` are its own: the candidates run with their methods'
defaults.

Candidates are independent: the search is a map over (method, n_regions) pairs.
"""

from __future__ import annotations

import numpy as np

from hwpts.errors import IdentificationError, ParameterError
from hwpts.identification.segmentation.base import Segmenter

DEFAULT_METHODS = ("average", "kmeans", "clustering", "alternating")


class AutoSegmenter(Segmenter):
    """Model selection by held-out free-run fit (module doc).

    Parameters
    ----------
    methods : sequence of str
        Candidate segmentation methods (registry names other than ``auto`` and ``hyperplane``).
    max_regions : int
        Largest number of regions tried (the estimator's ``n_regions`` when it is an int).
    scheme : {"blocked", "tail"}
        Blocked cross-validation over the whole record, or one held-out block at the end.
    n_folds : int
        Number of blocks of the ``blocked`` scheme (each needs at least 10 samples).
    holdout : float
        Share of the training samples held out at the end (``tail`` scheme).
    tolerance : float
        Percentage points within which a simpler / stable candidate is preferred.
    try_polish : bool
        Also score the chosen candidate with the simulation-error polish (``polish=True``) on the
        same blocks, and keep the polish if it raises the held-out fit by more than ``tolerance``.
    """

    name = "auto"
    uses_n_regions = False

    def __init__(self, methods=DEFAULT_METHODS, max_regions: int = 4, scheme: str = "blocked",
                 n_folds: int = 5, holdout: float = 0.25, tolerance: float = 0.5, try_polish: bool = True):
        self.methods = methods
        self.max_regions = max_regions
        self.scheme = scheme
        self.n_folds = n_folds
        self.holdout = holdout
        self.tolerance = tolerance
        self.try_polish = try_polish

    def segment(self, X, y, n_regions, structure, rng):  # pragma: no cover - used through PWARX
        raise IdentificationError("segmentation 'auto' selects whole models; use it through PWARX")

    def candidates(self, max_regions: int) -> list[tuple[str, int]]:
        from hwpts.identification.segmentation import SEGMENTATION_METHODS

        out = []
        for method in self.methods:
            if method not in SEGMENTATION_METHODS or method in ("auto", "hyperplane"):
                raise ParameterError(
                    f"auto: cannot try method {method!r}; choose among "
                    f"{[m for m in SEGMENTATION_METHODS if m not in ('auto', 'hyperplane')]}"
                )
            cls = SEGMENTATION_METHODS[method]
            if not cls.uses_n_regions:
                out.append((method, 2 if method == "zscore" else 1))
            else:
                top = min(max_regions, 3) if method == "threshold" else max_regions
                out.extend((method, s) for s in range(2, top + 1))
        return out

    def _blocks(self, n: int) -> list[tuple[int, int]]:
        if self.scheme == "blocked":
            k = self.n_folds
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 2:
                raise ParameterError(f"auto: n_folds must be an int >= 2, got {k!r}")
            if n // k < 10:
                raise ParameterError(f"auto: {n} training samples cannot make {k} blocks of >= 10 samples; "
                                     f"use fewer folds or scheme='tail'")
            edges = np.linspace(0, n, k + 1).round().astype(int)
            return [(int(edges[i]), int(edges[i + 1])) for i in range(k)]
        if self.scheme == "tail":
            if not 0.05 <= self.holdout <= 0.5:
                raise ParameterError(f"auto: holdout must be in [0.05, 0.5], got {self.holdout}")
            return [(n - int(round(n * self.holdout)), n)]
        raise ParameterError(f"auto: unknown scheme {self.scheme!r}; valid are ['blocked', 'tail']")

    def select(self, estimator, inputs: np.ndarray, output: np.ndarray) -> tuple[dict, list[dict]]:
        """Try every candidate; return (best parameters, table of every candidate)."""
        import warnings

        from hwpts.errors import HwptsError
        from hwpts.identification.selection import _score_candidate

        max_regions = self.max_regions
        if isinstance(estimator.n_regions, (int, np.integer)):
            max_regions = int(estimator.n_regions)
        blocks = self._blocks(output.shape[0])
        scheme = "blocked" if self.scheme == "blocked" else "forward"
        # the candidates get their methods' defaults: segmentation_params are auto's own
        base = {**estimator.get_params(), "segmentation_params": None}

        def scored(params, row):
            fits, row["rejected"] = _score_candidate(params, inputs, output, blocks, scheme)
            if fits is not None:
                row["block_fits_percent"] = [round(f, 3) for f in fits]
                row["heldout_fit_percent"] = float(np.mean(fits))
            return row

        rows = []
        for method, s in self.candidates(max_regions):
            params = {**base, "segmentation": method, "n_regions": s}
            row = scored(params, {"segmentation": method, "n_regions": s, "n_regions_fitted": None,
                                  "heldout_fit_percent": None, "block_fits_percent": None, "stable": None})
            if row["rejected"] is None:  # stability of the model fitted on all the data
                full = estimator.__class__(**params)
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        full.fit(inputs, output)
                    row["n_regions_fitted"] = int(full.n_regions_)
                    row["stable"] = bool(all(ss.stable for ss in full.state_space()))
                except HwptsError as error:
                    row["rejected"] = f"fit failed: {error}"
            rows.append(row)
        ok = [r for r in rows if r["rejected"] is None]
        if not ok:
            raise IdentificationError(
                "auto: every candidate model diverged in free run or failed; try other orders"
            )
        best_fit = max(r["heldout_fit_percent"] for r in ok)
        near = [r for r in ok if r["heldout_fit_percent"] >= best_fit - self.tolerance]
        near.sort(key=lambda r: (not r["stable"], r["n_regions_fitted"], -r["heldout_fit_percent"]))
        chosen = near[0]
        choice = {"segmentation": chosen["segmentation"], "n_regions": chosen["n_regions"],
                  "segmentation_params": None}
        if self.try_polish and not base.get("polish"):
            # the polish keeps the partition, so no fit on all the data here: the winner's refit
            # follows anyway
            row = scored({**base, **choice, "polish": True},
                         {"segmentation": chosen["segmentation"], "n_regions": chosen["n_regions"], "polish": True,
                          "heldout_fit_percent": None, "block_fits_percent": None})
            rows.append(row)
            # the same rule as between candidates: a stable model is preferred only within
            # ``tolerance``; the polish must gain more than that (and not diverge on any block)
            if row["rejected"] is None and row["heldout_fit_percent"] > chosen["heldout_fit_percent"] + self.tolerance:
                chosen = row
                choice["polish"] = True
        chosen["chosen"] = True
        return choice, rows
