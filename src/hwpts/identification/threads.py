"""One thread for the numerical libraries, entered once.

Every matrix of the identification is small (tens of columns): threaded BLAS and OpenMP gain
nothing there and, on a busy machine, spin-wait for cores (an SVD of 30,000 x 45 took 1.2 s with
two threads beside another job, 0.02 s with one; scikit-learn's k-means 30x slower). So the model
search, the polish, k-means and the nearest-neighbour search each run under
:func:`single_threaded`. threadpoolctl finds the loaded libraries by scanning the process's
memory map on every entry (4 ms each, 0.1 s of a Silverbox search entered 27 times): inside an
outer :func:`single_threaded` that already limits every library the nested entries are skipped.
"""

from __future__ import annotations

import contextlib
from contextvars import ContextVar

from threadpoolctl import threadpool_limits

__all__ = ["single_threaded"]

_ALL_LIMITED: ContextVar[bool] = ContextVar("hwpts_all_limited", default=False)


@contextlib.contextmanager
def single_threaded(user_api: str | None = None):
    """``threadpool_limits(limits=1, user_api=...)``, or nothing inside an outer call that limits
    every library (``user_api=None``)."""
    if _ALL_LIMITED.get():
        yield
        return
    if user_api is None:
        # threadpoolctl limits the libraries loaded at entry: load those the nested calls would
        # have limited (scipy's own BLAS, scikit-learn's OpenMP), which import lazily
        import scipy.linalg  # noqa: F401
        import sklearn.cluster  # noqa: F401
    with threadpool_limits(limits=1, user_api=user_api):
        token = _ALL_LIMITED.set(True) if user_api is None else None
        try:
            yield
        finally:
            if token is not None:
                _ALL_LIMITED.reset(token)
