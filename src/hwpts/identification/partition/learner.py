"""The partition learner: labels -> polyhedral regions (eq. 9), with boundary refinement.

A segmentation method gives every training row a region label; the learner turns the labels into
a multicategory linear classifier (polyhedra ``{x : H_i x + g_i <= 0}``, eq. 9) and then refines the
boundaries: each round fits the local models (eq. 17, trimming outliers), scores every row against
every mode with ``cost_ik = r_ik^2 / sigma^2 - log p_i(x_k)`` (residual plus the classifier's
confidence, which separates modes with equal parameters), and refits the classifier on the rows
whose best mode wins by ``confidence_margin``. Ambiguous rows near a boundary carry no information
about where it lies, so they are left to the classifier. Optionally (``sparse``) the columns the
boundaries hardly use are dropped (:meth:`PartitionLearner.sparse_partition`). Last, a boundary
that misclassifies some of its own training rows although they are separable is moved into the
gap between them (:meth:`PartitionLearner.sharpen`).
"""

from __future__ import annotations

import warnings

import numpy as np
from sklearn.base import BaseEstimator

from hwpts.errors import DataError, ParameterError
from hwpts.identification.partition.polyhedra import fit_linear_partition

__all__ = ["PartitionLearner", "drop_empty_regions", "noise_variance", "confident_rows", "TRIM"]

TRIM = 3.0  # outlier threshold (robust std) of the local least squares of learned partitions
SEPARABLE_C = 1e8  # the classifier's regularisation on labels it can separate exactly (sharpen)
POOL = 20  # the refinement rounds draw their classifier rows from at most POOL x classifier_rows rows


def dropped_message(before: int, after: int, path: str = "") -> str:
    """The warning's words for ``before - after`` of ``before`` regions dropped (``path``: the
    counts in between, `` (26 -> 11 -> 8)``)."""
    gone = before - after
    return (f"{gone} of {before} regions received no training sample and {'was' if gone == 1 else 'were'} "
            f"dropped{path}; the model has {after} region{'' if after == 1 else 's'}")


def drop_empty_regions(labels, s):
    """Labels renumbered without the regions that hold no row, and the number left (with a
    :class:`~hwpts.identification.local_models.RegionWarning` when some were dropped)."""
    from hwpts.identification.local_models import RegionWarning

    counts = np.bincount(labels, minlength=s)
    keep = np.flatnonzero(counts > 0)
    if keep.size == s:
        return labels, s
    warnings.warn(RegionWarning(dropped_message(s, keep.size), "dropped", before=int(s), after=int(keep.size)),
                  stacklevel=3)
    remap = np.full(s, -1)
    remap[keep] = np.arange(keep.size)
    return remap[labels], int(keep.size)


def noise_variance(squared_residuals, scale: float = 1.0) -> float:
    """The residual variance from the rows' squared residuals under their own mode, robustly: the
    median over 0.4549 (the median of a chi-square with one degree of freedom), plus ``1e-12``
    of ``scale`` (the data's variance) so that an exact fit does not divide by zero."""
    return float(np.median(squared_residuals)) / 0.4549 + 1e-12 * scale


def confident_rows(cost, labels, margin: float, n_labels: int, min_rows: int):
    """Rows whose best entry of ``cost`` (rows x modes) beats the second by more than ``margin``:
    the rows that say where a mode lives (a row two modes explain alike does not). Every row when
    that would leave some label of ``labels`` (``0 .. n_labels-1``) with fewer than ``min_rows``."""
    ordered = np.sort(cost, axis=1)
    confident = (ordered[:, 1] - ordered[:, 0]) > margin
    if np.bincount(labels[confident], minlength=n_labels).min() < min_rows:
        confident[:] = True
    return confident


class PartitionLearner(BaseEstimator):
    """Region classifier and boundary refinement (module doc).

    Parameters
    ----------
    refinement_rounds : int
        Boundary refinement rounds (0: the classifier of the labels as they are).
    C : float
        Inverse regularisation of the multinomial logistic classifier.
    ridge : float
        Ridge penalty of the local least squares inside the rounds.
    sparse : bool
        Drop the columns the boundaries hardly use (see :meth:`sparse_partition`).
    confidence_margin : float
        Cost margin by which a row's best mode must win for the row to train the classifier.
    classifier_rows : int
        Most rows the classifier is refitted on in a round (half nearest the boundaries).
    sparse_tol : float
        A column whose boundary weight is below this share of the largest is dropped.
    trim : float
        Outlier threshold (robust standard deviations) of the local least squares.
    separable_C : float or None
        When the regularised classifier misclassifies some of its training rows and they can be
        separated exactly, the boundaries are refitted with this (weak) regularisation, which puts
        them in the gaps between the regions' rows (:meth:`sharpen`); ``None``: never.
    random_state : int or None
    """

    def __init__(self, *, refinement_rounds: int = 3, C: float = 1e4, ridge: float = 0.0, sparse: bool = True,
                 confidence_margin: float = 4.0, classifier_rows: int = 6000, sparse_tol: float = 0.05,
                 trim: float = TRIM, separable_C=SEPARABLE_C, random_state=None):
        self.refinement_rounds = refinement_rounds
        self.C = C
        self.ridge = ridge
        self.sparse = sparse
        self.confidence_margin = confidence_margin
        self.classifier_rows = classifier_rows
        self.sparse_tol = sparse_tol
        self.trim = trim
        self.separable_C = separable_C
        self.random_state = random_state

    def check_params(self) -> None:
        """One line naming a setting that is not what it takes (before any fit)."""
        from hwpts.identification.settings import check_bool, check_count, check_number, check_random_state

        owner = "PartitionLearner: "
        check_count(self.refinement_rounds, "refinement_rounds", 0, owner)
        check_number(self.C, "C", strict=True, owner=owner, finite=False)  # inf: no regularisation
        check_number(self.ridge, "ridge", owner=owner)
        check_bool(self.sparse, "sparse", owner)
        check_number(self.confidence_margin, "confidence_margin", owner=owner, finite=False)
        check_count(self.classifier_rows, "classifier_rows", 100, owner)
        check_number(self.sparse_tol, "sparse_tol", owner=owner)
        for name in ("trim", "separable_C"):  # None: no trimming (fit_local_models), no sharpening
            if getattr(self, name) is not None:
                check_number(getattr(self, name), name, strict=True, owner=owner, finite=False)
        check_random_state(self.random_state, owner)

    @staticmethod
    def _check_rows(X, y, labels, s):
        """``(X, y, labels)`` as arrays: X (n, p) finite, y (n,) finite, labels whole numbers in
        ``0 .. s-1`` (a label of -1 or 1.5 is no region)."""
        from hwpts.identification.settings import is_count

        if not is_count(s, 1):
            raise ParameterError(f"PartitionLearner: s (the number of regions) must be an int >= 1, got {s!r}")
        from hwpts.dataset import dense_real

        X, y = dense_real(X, "X"), dense_real(y, "y")
        raw = np.asarray(labels)
        if X.ndim != 2 or y.ndim != 1 or raw.ndim != 1 or not X.shape[0] == y.shape[0] == raw.shape[0]:
            raise DataError(f"PartitionLearner: expected X of shape (n, p), y and labels of shape (n,), got "
                            f"{X.shape}, {y.shape} and {raw.shape}")
        if X.shape[0] == 0:
            raise DataError("PartitionLearner: X and y must hold at least one row")
        from hwpts.identification.regressors import check_values

        try:
            check_values("X", X)
            check_values("y", y)
        except DataError as error:
            raise DataError(f"PartitionLearner: {error}") from None
        if raw.dtype.kind not in "iu" and not (raw.dtype.kind in "bf" and np.array_equal(raw, np.round(raw))):
            raise DataError(f"PartitionLearner: labels must be whole numbers 0 .. {s - 1}, got values of type "
                            f"{raw.dtype}")
        labels = raw.astype(np.int64)
        if labels.min() < 0 or labels.max() >= s:
            raise DataError(f"PartitionLearner: labels must lie in 0 .. {s - 1}, got {labels.min()} .. {labels.max()}")
        return X, y, labels

    @staticmethod
    def _check_columns(columns, n_columns):
        """``columns`` as a sorted list of distinct column indices of X (``None``: every column)."""
        if columns is None:
            return None
        values = list(np.atleast_1d(np.asarray(columns, dtype=object)))
        if not values or any(isinstance(c, bool) or not isinstance(c, (int, np.integer)) or not 0 <= c < n_columns
                             for c in values) or len(set(values)) != len(values):
            raise ParameterError(f"PartitionLearner: columns must be distinct indices of X's columns 0 .. "
                                 f"{n_columns - 1} (at least one) or None, got {columns!r}")
        return sorted(int(c) for c in values)

    def learn(self, X, y, labels, s, constant=True, columns=None, init=None):
        """``(labels, partition, sparse_columns)`` for the rows ``X`` labelled ``labels``
        (``0 .. s-1``); ``columns``: regressor columns the classifier may use (default all);
        ``init``: a classifier of these labels to start the first fit from (a warm start);
        ``sparse_columns`` is None unless the sparse step dropped some."""
        from hwpts.identification.local_models import fit_local_models

        self.check_params()
        X, y, labels = self._check_rows(X, y, labels, s)
        columns = self._check_columns(columns, X.shape[1])
        rng = np.random.default_rng(self.random_state)
        # the first classifier on at most classifier_rows rows drawn at random (every region kept):
        # far more rows hardly move a logistic boundary and cost a Newton step each
        first = self._subsample(labels, s, rng)
        train_X, train_labels = X[first], labels[first]
        partition = fit_linear_partition(train_X, train_labels, s, C=self.C, columns=columns, init=init)
        labels = partition.predict(X)
        rounds = self.refinement_rounds if s > 1 else 0
        p = X.shape[1] + 1
        for _ in range(rounds):
            labels, s = drop_empty_regions(labels, s)
            if s == 1:
                break
            local = fit_local_models(X, y, labels, s, constant, ("affine",) * s, self.ridge, warn=False, trim=self.trim)
            R = local.residuals(X, y) ** 2
            assigned = R[np.arange(len(y)), labels]
            sigma2 = noise_variance(assigned, np.var(y) + 1e-300)
            logp = partition.log_proba(X) if partition.n_regions == s else None
            cost = R / sigma2 - (logp if logp is not None else 0.0)
            proposal = np.argmin(cost, axis=1)
            confident = confident_rows(cost, proposal, self.confidence_margin, s, p)
            confident = self._informative(confident, logp, rng)
            train_X, train_labels = X[confident], proposal[confident]
            previous = partition if partition.n_regions == s else None
            partition = fit_linear_partition(train_X, train_labels, s, C=self.C, columns=columns, init=previous)
            new_labels = partition.predict(X)
            if np.array_equal(new_labels, labels):
                break
            labels = new_labels
        sparse_columns = None
        if self.sparse and s > 1:  # (s == 1 only when a round emptied all but one region)
            sparse = self.sparse_partition(train_X, train_labels, partition, s, columns)
            if sparse is not None:
                partition, sparse_columns = sparse
                labels = partition.predict(X)
        cols = columns if sparse_columns is None else sparse_columns
        sharp = self.sharpen(train_X, train_labels, partition, s, cols)
        if sharp is not partition:
            partition, labels = sharp, sharp.predict(X)
        # regions emptied by the last round or by the sparse classifier: refit on the ones left
        labels, s = drop_empty_regions(labels, s)
        if partition.n_regions != s:
            partition = fit_linear_partition(X, labels, s, C=self.C, columns=cols)
            labels = partition.predict(X)
            if s == 1:
                sparse_columns = None
        return labels, partition, sparse_columns

    def sparse_partition(self, X, labels, partition, s, columns=None):
        """``(classifier, columns)`` refitted on the columns its boundaries use, or None.

        ``X, labels`` are the classifier's own training rows (the last refinement round's confident
        rows). A column is used when its weight in some boundary normal ``w_i - w_j`` (standardised
        coordinates) reaches ``sparse_tol`` of that normal's largest weight. The reduced classifier
        is kept only if it misclassifies no more of those rows than the full one, plus
        ``max(1, 0.1 %)`` of them; if it is refused, the columns under a tenth of ``sparse_tol``
        alone are tried (a boundary with a small but real slope in one column keeps that column and
        still drops the ones it does not use at all).
        """
        W, _ = partition.scores
        sd = X.std(axis=0)
        sd[sd == 0] = 1.0
        weight = np.zeros(X.shape[1])  # largest relative weight of each column over the normals
        for i in range(s):
            for j in range(i + 1, s):
                normal = np.abs(W[i] - W[j]) * sd
                if normal.max() > 0:
                    weight = np.maximum(weight, normal / normal.max())
        allowed = np.zeros(X.shape[1], dtype=bool)
        allowed[columns if columns is not None else slice(None)] = True
        errors_full = None
        tried = None
        for tol in (self.sparse_tol, self.sparse_tol / 10):
            used = allowed & (weight >= tol)
            if not used.any() or used.sum() == allowed.sum() or (tried is not None and np.array_equal(used, tried)):
                continue
            tried = used
            if errors_full is None:
                errors_full = int(np.sum(partition.predict(X) != labels))
            reduced = fit_linear_partition(X, labels, s, C=self.C, columns=np.flatnonzero(used))
            if int(np.sum(reduced.predict(X) != labels)) <= errors_full + max(1, int(0.001 * labels.size)):
                return reduced, np.flatnonzero(used)
        return None

    def sharpen(self, X, labels, partition, s, columns=None):
        """The classifier refitted with ``separable_C`` (warm-started from ``partition``) when
        ``partition`` misclassifies some rows of ``X`` (its own training rows) and the refit
        separates every one of them by its label; else ``partition`` itself.

        On separable labels the regularised (``C``) logistic boundary can be pulled across rows by
        the log-loss of the many rows near it; as the regularisation vanishes its direction tends
        to the maximum-margin separator (Rosset, Zhu & Hastie 2004), midway in the gap. Measured: a
        two-mode system switching on the sign of ``y(k-1)`` (2,000 samples) had its boundary at
        ``y(k-1) = 7e-4`` with ``C = 1e4``, beyond a training row at 3e-5, and lost 5 points of
        one-step fit to the validation samples in between (each costs the jump between the modes);
        sharpened, 99.9 % (the true partition's). A boundary that already separates its rows is
        kept: those rows are the confident ones, and the ambiguous rows left out open a gap wider
        than the data's, whose middle is no better an estimate (sharpening there too lowered the
        zoo's ``hit_cake`` from 75.2 to 73.6 % and ``hit_1d_3modes`` from 85.8 to 85.2 %; a weaker
        ``C`` everywhere, 1e6 or 1e8, lowered them as much).
        """
        if self.separable_C is None or s < 2 or np.array_equal(partition.predict(X), labels):
            return partition
        sharp = fit_linear_partition(X, labels, s, C=self.separable_C, columns=columns, init=partition)
        if np.array_equal(sharp.predict(X), labels):
            return sharp
        return partition

    def _subsample(self, labels, s, rng):
        """Indices of at most ``classifier_rows`` rows drawn at random, all rows of a small region kept."""
        n = labels.size
        limit = int(self.classifier_rows)
        if n <= limit:
            return np.arange(n)
        keep = np.zeros(n, dtype=bool)
        keep[rng.choice(n, limit, replace=False)] = True
        counts = np.bincount(labels, minlength=s)
        for r in np.flatnonzero((counts > 0) & (np.bincount(labels[keep], minlength=s) < 50)):
            keep[labels == r] = True  # a rare region keeps every row it has
        return np.flatnonzero(keep)

    def _informative(self, mask, logp, rng):
        """At most ``classifier_rows`` rows of ``mask`` for the classifier: the half nearest the
        current boundaries (smallest gap between the two largest class scores) and a random half
        of the rest, both out of at most :data:`POOL` x ``classifier_rows`` rows drawn at random.
        Far-away rows hardly move a near-separable logistic boundary."""
        limit = int(self.classifier_rows)
        idx = np.flatnonzero(mask)
        if idx.size <= limit or logp is None:
            return mask
        if idx.size > POOL * limit:
            # the nearest of a random pool: the nearest ``limit / 2`` of a million rows hug the
            # current boundaries so closely that the refit cannot move them (the zoo's
            # ``pwarx_random`` with 1e6 samples: one-step fit 90.99 % on three data sets, against
            # 99.94-99.95 % from a pool, as with 300,000 samples)
            idx = np.sort(rng.choice(idx, POOL * limit, replace=False))
        top2 = np.sort(logp[idx], axis=1)[:, -2:]
        gap = top2[:, 1] - top2[:, 0]
        order = np.argsort(gap)
        near = idx[order[: limit // 2]]
        rest = idx[order[limit // 2:]]
        far = rng.choice(rest, limit - near.size, replace=False)
        out = np.zeros_like(mask)
        out[near] = True
        out[far] = True
        return out
