"""Accuracy measures used across the field.

- :func:`fit_percent`: NRMSE fit ``100 * (1 - ||y - yhat|| / ||y - mean(y)||)``.
- :func:`rmse`.
- :func:`held_out_fit`: a held-out block's fit in the model search (its own, or against the whole
  output's spread where the output rests over the block).
- :func:`region_accuracy`: share of samples in the true mode, under the best one-to-one matching
  of estimated to true regions (Hungarian algorithm, ``scipy.optimize.linear_sum_assignment``).
- :func:`parameter_error`: max relative error of the matched ``theta_i``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from hwpts.errors import DataError

__all__ = ["fit_percent", "rmse", "region_accuracy", "best_permutation", "parameter_error"]


def _signal(values, label: str) -> np.ndarray:
    """One signal as a 1-D float array: a column or row vector is one; a matrix, complex or
    non-numeric values are refused (a cast would flatten, drop the imaginary part or fail)."""
    arr = np.asarray(values)
    if np.iscomplexobj(arr):
        raise DataError(f"{label} is complex; a fit is scored on real signals")
    try:
        arr = arr.astype(float)
    except (TypeError, ValueError):
        raise DataError(f"{label} must hold numbers, got values of type {arr.dtype}") from None
    if arr.ndim > 1 and sum(d > 1 for d in arr.shape) > 1:
        raise DataError(f"{label} must be one signal (1-D), got shape {arr.shape}")
    return arr.ravel()


def _pair(y, yhat):
    y = _signal(y, "the measured output")
    yhat = _signal(yhat, "the prediction")
    if y.shape != yhat.shape:
        raise DataError(f"measured and predicted outputs differ in length: {y.size} vs {yhat.size}")
    if y.size == 0:
        raise DataError("cannot score an empty signal")
    if not np.all(np.isfinite(y)):
        raise DataError(f"the measured output has {int(np.sum(~np.isfinite(y)))} non-finite value(s) "
                        f"(NaN or inf); a score needs every measured sample")
    return y, yhat


def fit_percent(y, yhat) -> float:
    """NRMSE fit in percent; ``nan`` when ``yhat`` is not finite (a diverged simulation).

    Raises :class:`DataError` for a constant ``y`` (the fit is undefined).

    >>> round(fit_percent([1.0, 2.0, 3.0], [1.0, 2.0, 3.5]), 3)
    64.645
    """
    y, yhat = _pair(y, yhat)
    if not np.all(np.isfinite(yhat)):
        return float("nan")
    scale = max(float(np.max(np.abs(y))), float(np.max(np.abs(yhat))))
    if scale > 1e150 or 0 < scale < 1e-100:
        # the norms' squares would overflow (a 1e160 signal scored nan) or lose their digits in
        # subnormal numbers (a 1e-160 signal scored 89.995 % for 89.986 %): scale both first
        y, yhat = y / scale, yhat / scale
    den = np.linalg.norm(y - y.mean())
    if den == 0:
        if np.ptp(y) > 0:  # it varies, by less than the squares can hold (1e-200)
            raise DataError(f"fit % is undefined: the measured output varies by {np.ptp(y):.3g} only, below what "
                            f"its squares can hold; rescale it")
        raise DataError("fit % is undefined for a constant measured output")
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / den))


REST = 1e-9  # a held-out block whose output's spread is at most this share of the record's rests


def held_out_fit(measured, predicted, spread) -> float:
    """Fit % of ``predicted`` on a held-out block of the model search: the block's own fit %
    (:func:`fit_percent`), or, where the output rests over the block (a tank empty, a rig idle: its
    own fit % is undefined, or a rounding error's where its spread is at most :data:`REST` of the
    record's), ``100 (1 - RMSE / spread)`` against the ``spread`` (standard deviation)
    of the whole output searched; ``nan`` where ``predicted`` is not finite (a diverged run).

    The search refused a record with such a block ("the output is constant over held-out block 4
    of 5"). Scoring every block against the whole spread instead (ranking by the blocks' mean
    RMSE) was tried and dropped: pick_and_place's blocks differ in motion, and that ranking chose a
    model of 52.6 % test fit where the blocks' own fits choose one of 85.9 %.

    >>> round(held_out_fit([1.0, 2.0, 3.0], [1.0, 2.0, 3.5], spread=5.0), 3)
    64.645
    >>> round(held_out_fit([0.0, 0.0], [0.0, 0.5], spread=1.0), 3)
    64.645
    """
    if not spread > 0:
        raise DataError(f"a held-out fit needs the spread of an output that varies, got {spread!r}")
    y = np.asarray(measured, dtype=float)
    if y.size and np.all(np.isfinite(y)):
        top = max(float(np.max(np.abs(y))), float(spread))
        if np.std(y / top) > REST * spread / top:  # it moves: its own fit %, validated there
            return fit_percent(measured, predicted)
    y, yhat = _pair(measured, predicted)
    if not np.all(np.isfinite(yhat)):
        return float("nan")
    # scaled first: the squares of a 1e160 signal overflow (fit_percent does the same)
    scale = max(float(np.max(np.abs(y))), float(np.max(np.abs(yhat))), float(spread))
    rmse = float(np.sqrt(np.mean(((y - yhat) / scale) ** 2)))
    return 100.0 * (1.0 - rmse / (spread / scale))


def output_spread(y) -> float:
    """Standard deviation of the output ``y`` (scaled first: a 1e160 signal's squares overflow)."""
    scale = float(np.max(np.abs(y)))
    return 0.0 if scale == 0.0 else float(np.std(y / scale)) * scale


def rmse(y, yhat) -> float:
    """Root-mean-square error (``nan`` when ``yhat`` is not finite)."""
    y, yhat = _pair(y, yhat)
    if not np.all(np.isfinite(yhat)):
        return float("nan")
    return float(np.sqrt(np.mean((y - yhat) ** 2)))


def _labels(values, label: str) -> np.ndarray:
    """Region labels as a 1-D int array: whole numbers, ``-1`` (or any negative) for "no region"
    (the initial conditions of :meth:`PWARX.predict_regions` and of the zoo's ``modes``)."""
    arr = np.asarray(values)
    if arr.dtype.kind not in "biu":
        try:
            as_float = arr.astype(float)
        except (TypeError, ValueError):
            raise DataError(f"{label} must be region numbers, got values of type {arr.dtype}") from None
        if not np.all(np.isfinite(as_float)) or np.any(as_float != np.round(as_float)):
            raise DataError(f"{label} must be whole region numbers (-1 for none), got a non-integer or NaN value")
        arr = as_float
    return np.asarray(arr, dtype=np.int64).ravel()


def best_permutation(true_labels, est_labels, n_true: int | None = None, n_est: int | None = None) -> dict:
    """Matching estimated region -> true region maximising agreement (``linear_sum_assignment``);
    samples without a region (a negative label) on either side are left out of the count."""
    t = _labels(true_labels, "true_labels")
    e = _labels(est_labels, "est_labels")
    if t.shape != e.shape:
        raise DataError(f"label arrays must be equal in length: {t.size} vs {e.size}")
    both = (t >= 0) & (e >= 0)
    t, e = t[both], e[both]
    n_t = n_true or (int(t.max()) + 1 if t.size else 1)
    n_e = n_est or (int(e.max()) + 1 if e.size else 1)
    if t.size and (t.max() >= n_t or e.max() >= n_e):
        raise DataError(f"a label is beyond the {n_t} true or {n_e} estimated regions")
    counts = np.zeros((n_e, n_t))
    np.add.at(counts, (e, t), 1)
    rows, cols = linear_sum_assignment(counts, maximize=True)
    return {int(r): int(c) for r, c in zip(rows, cols)}


def region_accuracy(true_labels, est_labels) -> float:
    """Share (0..1) of samples whose estimated region matches the true one, best permutation.

    Samples whose true label is negative (no mode: the initial conditions) are left out; an
    estimated negative label where a true region exists counts as a miss.

    >>> region_accuracy([-1, -1, 0, 0, 1], [-1, -1, 1, 1, 0])
    1.0
    """
    t = _labels(true_labels, "true_labels")
    e = _labels(est_labels, "est_labels")
    if t.shape != e.shape or t.size == 0:
        raise DataError(f"label arrays must be non-empty and equal in length: {t.size} vs {e.size}")
    keep = t >= 0
    if not keep.any():
        raise DataError("no sample has a true region (every true label is negative)")
    t, e = t[keep], e[keep]
    perm = best_permutation(t, e)
    table = np.array([perm.get(v, -1) for v in range(max(int(e.max()), 0) + 1)])
    mapped = np.where(e >= 0, table[np.maximum(e, 0)], -1)
    return float(np.mean(mapped == t))


def parameter_error(theta_true, theta_est, true_labels=None, est_labels=None) -> float:
    """Max over matched modes of ||theta_est - theta_true|| / ||theta_true|| (relative, 2-norm).

    Modes are matched by the best permutation of the labels when given, else by the best
    permutation of the parameter distances.
    """
    T = np.atleast_2d(np.asarray(theta_true, dtype=float))
    E = np.atleast_2d(np.asarray(theta_est, dtype=float))
    for label, arr in (("theta_true", T), ("theta_est", E)):
        if arr.ndim != 2 or arr.size == 0 or not np.all(np.isfinite(arr)):
            raise DataError(f"{label} must be a finite (modes, parameters) array, got shape {arr.shape}"
                            f"{'' if arr.size == 0 or np.all(np.isfinite(arr)) else ' with NaN or inf'}")
    if T.shape[1] != E.shape[1]:
        raise DataError(f"parameter vectors differ in length: {T.shape[1]} vs {E.shape[1]}")
    if true_labels is not None and est_labels is not None:
        perm = best_permutation(true_labels, est_labels, T.shape[0], E.shape[0])
        pairs = [(e, t) for e, t in perm.items()]
    else:
        dist = np.linalg.norm(E[:, None, :] - T[None, :, :], axis=2)
        rows, cols = linear_sum_assignment(dist)
        pairs = list(zip(rows, cols))
    errs = [np.linalg.norm(E[e] - T[t]) / max(np.linalg.norm(T[t]), 1e-12) for e, t in pairs]
    return float(max(errs))
