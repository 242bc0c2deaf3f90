"""``auto``: choose the segmentation method and the number of regions on the training data only.

The training data are split into a head (default 75 %) and a held-out tail. Every candidate
(``average`` with one region; each learned method with 2 .. ``max_regions`` regions) is fitted on
the head and *simulated in free run* on the tail, from measured initial conditions. A candidate
whose free run diverges, on the tail or over the whole training record, is rejected (a naive
k-means PWARX diverges on the actuator data); among the rest, the best tail fit wins, and a
candidate within ``tolerance`` percentage points of it is preferred when it has fewer regions or
only stable modes (state-space poles inside the unit circle, eq. 7). The winner is refitted on all
the training data.

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
    holdout : float
        Share of the training samples held out at the end for the free-run check.
    tolerance : float
        Percentage points within which a simpler / stable candidate is preferred.
    """

    name = "auto"
    uses_n_regions = False

    def __init__(self, methods=DEFAULT_METHODS, max_regions: int = 4, holdout: float = 0.25,
                 tolerance: float = 0.5):
        self.methods = methods
        self.max_regions = max_regions
        self.holdout = holdout
        self.tolerance = tolerance

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

    def select(self, estimator, inputs: np.ndarray, output: np.ndarray) -> tuple[dict, list[dict]]:
        """Try every candidate; return (best parameters, table of every candidate)."""
        from sklearn.base import clone

        from hwpts.identification.metrics import fit_percent

        if not 0.05 <= self.holdout <= 0.5:
            raise ParameterError(f"auto: holdout must be in [0.05, 0.5], got {self.holdout}")
        max_regions = self.max_regions
        if isinstance(estimator.n_regions, (int, np.integer)):
            max_regions = int(estimator.n_regions)
        n = output.shape[0]
        n_tail = int(round(n * self.holdout))
        head = slice(0, n - n_tail)
        tail = slice(n - n_tail, n)
        rows = []
        for method, s in self.candidates(max_regions):
            params = {"segmentation": method, "n_regions": s}
            cand = clone(estimator).set_params(**params)
            row = {"segmentation": method, "n_regions": s, "tail_fit_percent": None,
                   "train_fit_percent": None, "stable": None, "rejected": None}
            try:
                import warnings

                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    cand.fit(inputs[head], output[head])
                    sim_tail = cand.simulate(inputs[tail], output[tail])
                    sim_all = cand.simulate(inputs, output)
            except IdentificationError as error:
                row["rejected"] = f"fit failed: {error}"
                rows.append(row)
                continue
            m = cand.structure_.max_lag
            row["n_regions"] = int(cand.n_regions_)
            row["stable"] = bool(all(ss.stable for ss in cand.state_space()))
            if sim_tail.diverged or sim_all.diverged:
                row["rejected"] = "free run diverged"
            else:
                row["tail_fit_percent"] = fit_percent(output[tail][m:], sim_tail.output[m:])
                row["train_fit_percent"] = fit_percent(output[m:], sim_all.output[m:])
            rows.append(row)
        ok = [r for r in rows if r["rejected"] is None]
        if not ok:
            raise IdentificationError(
                "auto: every candidate model diverged in free run or failed; try other orders"
            )
        best_fit = max(r["tail_fit_percent"] for r in ok)
        near = [r for r in ok if r["tail_fit_percent"] >= best_fit - self.tolerance]
        near.sort(key=lambda r: (not r["stable"], r["n_regions"], -r["tail_fit_percent"]))
        chosen = near[0]
        chosen["chosen"] = True
        return {"segmentation": chosen["segmentation"], "n_regions": chosen["n_regions"]}, rows
