"""Time-series cross-validation splitters (scikit-learn's splitter interface).

- :class:`BlockedSplit`: blocked cross-validation (Bergmeir & Benitez 2012): the record is cut into
  ``n_splits`` contiguous blocks; each block is held out in turn and the model is fitted on the
  others (the data before and after it, joined). Every regime of the record is validated.
- scikit-learn's :class:`~sklearn.model_selection.TimeSeriesSplit` (forward chaining: fitted on
  the past only) works unchanged, as does any splitter that yields ``(train, test)`` index arrays
  with a contiguous ``test``.

A training set that joins two stretches of the record has a *gap*: the model search passes its
position to :meth:`hwpts.identification.PWARX.fit` (``breaks``), which drops the regressor rows
whose lag window spans it, so no regressor mixes samples from both sides.
"""

from __future__ import annotations

import numpy as np
from sklearn.model_selection import TimeSeriesSplit

from hwpts.errors import ParameterError

__all__ = ["BlockedSplit", "TimeSeriesSplit", "HoldoutSplit", "breaks_of"]


class BlockedSplit:
    """``n_splits`` contiguous test blocks covering the record; train on the rest.

    Parameters
    ----------
    n_splits : int
        Number of blocks (>= 2).
    min_block : int
        Smallest block length; :meth:`split` refuses records too short for it.
    """

    def __init__(self, n_splits: int = 5, *, min_block: int = 10):
        if isinstance(n_splits, bool) or not isinstance(n_splits, (int, np.integer)) or n_splits < 2:
            raise ParameterError(f"BlockedSplit: n_splits must be an int >= 2, got {n_splits!r}")
        self.n_splits = int(n_splits)
        self.min_block = int(min_block)

    def get_n_splits(self, X=None, y=None, groups=None) -> int:
        """Number of (train, test) pairs."""
        return self.n_splits

    def split(self, X, y=None, groups=None):
        """Yield ``(train, test)`` index arrays: each contiguous block in turn held out, the rest for training."""
        n = len(X)
        if n // self.n_splits < self.min_block:
            raise ParameterError(f"{n} samples cannot make {self.n_splits} blocks of >= {self.min_block} samples")
        edges = np.linspace(0, n, self.n_splits + 1).round().astype(int)
        idx = np.arange(n)
        for i in range(self.n_splits):
            test = idx[edges[i]:edges[i + 1]]
            train = np.concatenate([idx[:edges[i]], idx[edges[i + 1]:]])
            yield train, test

    def __repr__(self) -> str:
        return f"BlockedSplit(n_splits={self.n_splits}, min_block={self.min_block})"


class HoldoutSplit:
    """One split: fitted on the first ``1 - test_size`` of the record, tested on the rest."""

    def __init__(self, test_size: float = 0.2):
        if not 0.0 < test_size < 1.0:
            raise ParameterError(f"HoldoutSplit: test_size must be in (0, 1), got {test_size!r}")
        self.test_size = float(test_size)

    def get_n_splits(self, X=None, y=None, groups=None) -> int:
        """Always 1."""
        return 1

    def split(self, X, y=None, groups=None):
        """Yield one ``(train, test)`` pair: the leading rows for training, the last ``test_size`` share held out."""
        n = len(X)
        cut = int(round((1.0 - self.test_size) * n))
        idx = np.arange(n)
        yield idx[:cut], idx[cut:]

    def __repr__(self) -> str:
        return f"HoldoutSplit(test_size={self.test_size})"


def breaks_of(train: np.ndarray) -> list[int]:
    """Positions in the training record (``train`` indices, increasing) where a stretch restarts."""
    train = np.asarray(train)
    return [int(k) for k in np.flatnonzero(np.diff(train) != 1) + 1]
