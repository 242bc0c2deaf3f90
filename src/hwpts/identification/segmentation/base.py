"""What every segmentation method returns, and the shared base class."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from sklearn.base import BaseEstimator

from hwpts.errors import DataError, ParameterError
from hwpts.identification.threads import single_threaded


@dataclass
class SegmentationResult:
    """Training samples assigned to regions.

    Attributes
    ----------
    labels : ndarray of int, shape (n_rows,)
        Region (0-based) of each training regressor row.
    n_regions : int
    partition : RegionPartition or None
        A partition fixed by the method itself (hyperplanes); ``None`` means the estimator learns
        one with a multicategory linear classifier over the regressors (paper eq. 9).
    refine : bool
        Whether the estimator may move samples between regions afterwards (boundary refinement).
    info : dict
        Method diagnostics (iterations, objective...), JSON-serialisable.
    """

    labels: np.ndarray
    n_regions: int
    partition: object = None
    refine: bool = True
    info: dict = field(default_factory=dict)


class Segmenter(BaseEstimator):
    """Base class, a scikit-learn estimator: ``__init__`` stores keyword-only parameters unchanged
    (so ``sklearn.base.clone`` and ``get_params``/``set_params`` work); :meth:`segment` does the work.

    ``segment(X, y, n_regions, structure, rng)`` receives the standard regressors ``X`` (eq. 7),
    targets ``y``, the requested number of regions, the :class:`RegressorStructure` and a numpy
    ``Generator``; it returns a :class:`SegmentationResult`.
    """

    name = "base"
    #: whether the method takes the number of regions from the caller
    uses_n_regions = True
    #: the number of regions a method that does not take it always makes (None: it takes it)
    fixed_regions: int | None = None
    #: whether the estimator learns the partition from the labels (then it may segment a subsample)
    learns_partition = False
    #: whether the method draws its own fixed partition on regressor columns, so that
    #: ``segment`` takes ``columns=`` (the indices a PWARX's ``partition_columns`` allows)
    restricts_columns = False
    #: whether ``segment`` returns the partition itself (its hyperplanes, its thresholds, one
    #: region) rather than labels a classifier is then learned from (``zscore``'s are: its rule
    #: labels the rows, the classifier draws the boundary)
    returns_partition = False

    @classmethod
    def takes_partition_columns(cls) -> bool:
        """Whether a PWARX's ``partition_columns`` shape this method's boundaries: a classifier
        learned on its labels uses them, a threshold split chooses its column among them; a
        partition the method returns whole (hyperplanes, one region) has none to restrict."""
        return cls.restricts_columns or not cls.returns_partition

    @classmethod
    def given_partition(cls) -> bool:
        """Whether the partition is the user's or the method's own rule (``average``, ``zscore``,
        ``hyperplane``), not one found on the data: no boundary to restrict to columns, none for
        a model search to choose."""
        return not (cls.learns_partition or cls.restricts_columns)

    def check_params(self) -> None:
        """Raise a one-line :class:`ParameterError` naming a setting of this method that is not
        what it takes (called before any fit, and by :meth:`segment`); the count of regions and the
        rows are checked where they are used."""

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:  # pragma: no cover
        """Assign the regressor rows ``X`` with targets ``y`` to ``n_regions`` regions; returns a :class:`SegmentationResult` (labels, and a partition when the method defines one)."""
        raise NotImplementedError

    @staticmethod
    def _check_rows(X, y, rng):
        """``(X, y, rng)`` as :meth:`segment` works on them: the regressor rows ``X`` (n, p) and
        their targets ``y`` (n,), finite, and ``rng`` a numpy ``Generator`` (an int or ``None``
        seeds one, as scikit-learn's ``random_state``); else one line naming the argument."""
        from hwpts.dataset import dense_real
        from hwpts.identification.regressors import check_values

        X, y = dense_real(X, "X"), dense_real(y, "y")
        if X.ndim != 2:
            raise DataError(f"X must be the regressor rows, shape (n, p); got shape {X.shape}")
        if y.ndim != 1 or y.shape[0] != X.shape[0]:
            raise DataError(f"y must be the targets of X's {X.shape[0]} rows, shape ({X.shape[0]},); got shape {y.shape}")
        check_values("X", X)
        check_values("y", y)
        if not isinstance(rng, np.random.Generator):
            if rng is not None and (isinstance(rng, bool) or not isinstance(rng, (int, np.integer)) or rng < 0):
                raise ParameterError(f"rng must be a numpy Generator, an int >= 0 or None, got {rng!r}")
            rng = np.random.default_rng(rng)
        return X, y, rng

    def _check_regions(self, n_regions, n_rows):
        if not isinstance(n_regions, (int, np.integer)) or n_regions < 1:
            raise ParameterError(f"n_regions must be an int >= 1, got {n_regions!r}")
        if n_regions > n_rows:
            raise ParameterError(f"n_regions={n_regions} exceeds the {n_rows} training regressors")


def standardize(X: np.ndarray) -> np.ndarray:
    """Columns scaled to zero mean and unit standard deviation (constant columns left at 0)."""
    sd = X.std(axis=0)
    sd[sd == 0] = 1.0
    return (X - X.mean(axis=0)) / sd


def fingerprint(*arrays) -> bytes:
    """A 16-byte hash of arrays' shapes, types and contents (keys of the segmenters' caches)."""
    import hashlib

    h = hashlib.blake2b(digest_size=16)
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.shape, a.dtype.str)).encode())
        h.update(a.data)
    return h.digest()


def _nbytes(value) -> int:
    """Bytes held by the arrays of a cached value (an array or a tuple of arrays and scalars)."""
    items = value if isinstance(value, tuple) else (value,)
    return int(sum(getattr(v, "nbytes", 0) for v in items))


_CACHES: list = []  # every BoundedCache made (module-level caches, a handful): see clear_caches


def clear_caches() -> None:
    """Empty the segmenters' caches (:class:`BoundedCache`): what a fresh process starts from, e.g.
    to time a model search as a user's first run (a second search on the same data in the same
    process reuses its threshold costs and clustering features: Silverbox 2.5 -> 1.4 s) or to free
    their memory (at most 128 MB each)."""
    for cache in _CACHES:
        cache.clear()


class BoundedCache(dict):
    """A small first-in-first-out cache (the segmenters' costs that do not depend on the number of
    regions, keyed by :func:`fingerprint` of their rows): at most ``maxsize`` entries and, if
    ``maxbytes`` is given, at most that many bytes of arrays."""

    def __init__(self, maxsize: int, maxbytes: int | None = None):
        super().__init__()
        self.maxsize = int(maxsize)
        self.maxbytes = maxbytes
        self._bytes = 0
        _CACHES.append(self)

    def get_or_compute(self, key, compute):
        """The value stored under ``key``, or ``compute()`` stored there (the oldest entries dropped
        when full; a value larger than ``maxbytes`` alone is returned, not stored)."""
        hit = self.get(key)
        if hit is None:
            hit = compute()
            size = _nbytes(hit)
            if self.maxbytes is not None and size > self.maxbytes:
                return hit
            while self and (len(self) >= self.maxsize
                            or (self.maxbytes is not None and self._bytes + size > self.maxbytes)):
                self._bytes -= _nbytes(self.pop(next(iter(self))))
            self[key] = hit
            self._bytes += size
        return hit

    def clear(self) -> None:
        """Drop every entry."""
        super().clear()
        self._bytes = 0


def kmeans_labels(F: np.ndarray, n_clusters: int, rng, n_init: int = 10, sample_weight=None,
                  max_fit_samples: int = 4000) -> np.ndarray:
    """k-means labels of the rows of ``F``; centres fitted on a random subset of at most
    ``max_fit_samples`` rows (k-means cost grows with n, the centres do not need every row)."""
    from sklearn.cluster import KMeans

    n = F.shape[0]
    idx = np.arange(n)
    if n > max_fit_samples:
        idx = np.sort(rng.choice(n, max_fit_samples, replace=False))
    w = None if sample_weight is None else sample_weight[idx]
    km = KMeans(n_clusters=n_clusters, n_init=n_init, random_state=int(rng.integers(2**31 - 1)))
    # one OpenMP thread: on a busy machine scikit-learn's threaded Lloyd iterations spin-wait for
    # cores and run 30x slower than a single thread on these sizes (measured, 4,000 x 11 rows)
    with single_threaded("openmp"):
        km.fit(F[idx], sample_weight=w)
        return km.predict(F).astype(np.int64)
