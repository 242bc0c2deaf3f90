"""Local (per-region) affine models: least squares per region (paper eq. 17).

For a fixed assignment ``lambda_ki`` of samples to regions, eq. 17 decouples into one ordinary
least-squares problem per region::

    theta_i = argmin sum_{k in region i} (y_k - phi_k' theta_i)^2

solved here with column scaling (and an optional ridge penalty that leaves the offset free).
A region can also be a *constant* mode (``y = c_i``) or a *zero* mode (``y = 0``, the paper's third
region of eq. 18, ``omega_mA = 0 if h_i >= 3.5``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from hwpts.errors import IdentificationError, ParameterError

__all__ = ["RegionWarning", "LocalModels", "fit_local_models", "parameter_covariance", "MODEL_KINDS"]

MODEL_KINDS = ("affine", "constant", "zero")
ILL_CONDITIONED = 1e10


class RegionWarning(UserWarning):
    """A region has too few samples for its parameters, or its least squares is ill-conditioned,
    or regions were dropped for want of training samples.

    ``kind`` says which, with its numbers in ``details``: ``"starved"`` (``region``, 1-based;
    ``rows``, ``parameters``), ``"ill_conditioned"`` (``region``, ``condition``), ``"dropped"``
    (``before``, ``after``: the region counts); tools that collect the warnings of a fit use them
    (``hwpts identify`` reports a cascade of drops, or several ill-conditioned regions, in one line).
    """

    def __init__(self, message: str, kind: str | None = None, **details):
        super().__init__(message)
        self.kind = kind
        self.details = details


@dataclass
class LocalModels:
    """Per-region parameters.

    Attributes
    ----------
    theta : ndarray, shape (n_regions, n_features + 1)
        Row ``i`` is ``theta_i`` of eq. 5 over ``[x_k' 1]'``; the last entry is the offset
        (zero for a model without constant term).
    kinds : tuple of str
        ``"affine"``, ``"constant"`` or ``"zero"`` per region.
    n_samples : ndarray of int
        Training samples per region.
    condition : ndarray
        Condition number of each region's (column-scaled) least-squares matrix (nan if not fitted).
    covariance : ndarray, shape (n_regions, n_features + 1, n_features + 1)
        Covariance of each region's parameters from its least squares,
        ``sigma_i^2 (Phi_i' Phi_i)^-1`` with ``sigma_i^2 = RSS_i / (n_i - p)`` (the standard
        errors of MATLAB's ``getcov``); zero for a zero mode, ``nan`` where ``n_i <= p``.
    """

    theta: np.ndarray
    kinds: tuple
    n_samples: np.ndarray
    condition: np.ndarray
    covariance: np.ndarray | None = None

    @property
    def std(self) -> np.ndarray:
        """Standard errors of ``theta``, shape (n_regions, n_features + 1)."""
        return np.sqrt(np.clip(np.diagonal(self.covariance, axis1=1, axis2=2), 0.0, None))

    def predict(self, X: np.ndarray, regions: np.ndarray) -> np.ndarray:
        """y_k = phi_k' theta_{sigma(k)} (eq. 5)."""
        th = self.theta[regions]
        return np.einsum("ij,ij->i", X, th[:, :-1]) + th[:, -1]

    def residuals(self, X: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Residual of every sample under every mode, shape (n, n_regions)."""
        return y[:, None] - (X @ self.theta[:, :-1].T + self.theta[:, -1])


def _scaled(X: np.ndarray, constant: bool):
    """``(A, scale, mean)``: the regressors ``X`` centred (with a constant term: the offset is
    then the intercept's, fitted apart) and divided by each column's root mean square (1 for a
    zero column). Centred, neither a ridge penalty nor the minimum-norm solution of a
    rank-deficient region depends on where the signals' zeros are: on raw columns an input offset
    of 300 shrank a ridge-fitted input gain of 2.0 to 0.007, and a region whose input was constant
    put -2.16 or -100.8 on that input as the output's zero moved by 1000."""
    n = X.shape[0]
    mean = X.mean(axis=0) if constant and n else np.zeros(X.shape[1])
    A = X - mean if constant and n else X
    scale = np.sqrt(np.mean(A**2, axis=0)) if n else np.ones(X.shape[1])
    # a column constant in the region (an input held over all its rows) is zero once centred, not
    # its rounding scaled up to unit size and fitted as a regressor
    flat = ~(scale > 1e-12 * np.sqrt(np.mean(X**2, axis=0))) if n else np.zeros(X.shape[1], dtype=bool)
    if flat.any():
        A = A.copy() if A is X else A
        A[:, flat] = 0.0
    scale[flat | ~(scale > 1e-300)] = 1.0
    return A / scale, scale, mean


def _fit_region(X: np.ndarray, y: np.ndarray, constant: bool, ridge: float = 0.0):
    """``(theta, cond, G, scale, mean)``: least squares of one region (:func:`solve_region`) on
    the centred, column-scaled regressors (:func:`_scaled`), the intercept from the means, with
    the normal matrix ``G = A' A`` that :func:`parameter_covariance` needs (``None`` when it was
    not formed: a ridge, or the SVD path), so that it is not formed twice."""
    n, nf = X.shape
    A, scale, mean = _scaled(X, constant)
    ym = float(y.mean()) if constant and n else 0.0
    b = y - ym
    if ridge > 0:  # on the slopes only: the intercept is the means'
        A = np.vstack([A, np.sqrt(ridge * max(n, 1)) * np.eye(nf)])
        b = np.concatenate([b, np.zeros(nf)])
    coef = G = None
    if A.shape[0] >= 4 * A.shape[1]:  # tall: normal equations (fast), if well conditioned
        G = A.T @ A
        ev = np.linalg.eigvalsh(G) if nf else np.ones(1)
        cond = float(np.sqrt(ev[-1] / ev[0])) if ev[0] > 0 else float("inf")
        if cond < 1e6:
            coef = np.linalg.solve(G, A.T @ b)
    if coef is None:  # SVD least squares: robust to rank deficiency (minimum norm)
        coef, _, rank, sv = np.linalg.lstsq(A, b, rcond=None)
        cond = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    theta = np.zeros(nf + 1)
    theta[:nf] = coef / scale
    if constant:
        theta[nf] = ym - float(mean @ theta[:nf])
    return theta, cond, (G if ridge == 0 else None), scale, mean


def solve_region(X: np.ndarray, y: np.ndarray, constant: bool, ridge: float = 0.0) -> tuple[np.ndarray, float]:
    """Least squares (eq. 17) of one region on centred, column-scaled regressors; returns (theta, cond)."""
    theta, cond, _, _, _ = _fit_region(X, y, constant, ridge)
    return theta, cond


def parameter_covariance(X: np.ndarray, y: np.ndarray, theta: np.ndarray, constant: bool) -> np.ndarray:
    """Covariance ``sigma^2 (Phi' Phi)^-1`` of one region's least-squares parameters (eq. 17).

    ``sigma^2 = RSS / (n - p)``, the residual variance with ``p`` parameters; the matrix is over
    ``[x' 1]`` (offset last; its row and column are zero without a constant term). ``nan`` when the
    region has no more samples than parameters.
    """
    A, scale, mean = _scaled(np.asarray(X, dtype=float), constant)
    return _covariance(X, y, theta, constant, A.T @ A, scale, mean)


def _covariance(X, y, theta, constant, G, scale, mean) -> np.ndarray:
    """:func:`parameter_covariance` from the centred, column-scaled normal matrix ``G`` already
    formed: the slopes' ``sigma^2 G^-1`` (scaled back), and the intercept ``c - mean' beta`` of the
    centred fit's ``c`` (variance ``sigma^2 / n``, uncorrelated with the slopes)."""
    n, nf = X.shape
    cov = np.full((nf + 1, nf + 1), np.nan)
    p = nf + int(constant)
    if n <= p:
        return cov
    r = y - X @ theta[:nf] - theta[nf]
    sigma2 = float(r @ r) / (n - p)
    slopes = sigma2 * np.linalg.pinv(G) / np.outer(scale, scale)
    cov[:] = 0.0
    cov[:nf, :nf] = slopes
    if constant:
        cross = -slopes @ mean
        cov[:nf, nf] = cov[nf, :nf] = cross
        cov[nf, nf] = sigma2 / n + float(mean @ slopes @ mean)
    return cov


def fit_local_models(X: np.ndarray, y: np.ndarray, labels: np.ndarray, n_regions: int,
                     constant: bool = True, kinds=None, ridge: float = 0.0, warn: bool = True,
                     trim: float | None = None) -> LocalModels:
    """Least squares per region (paper eq. 17) for the assignment ``labels`` (0-based regions).

    ``trim`` (optional): refit once without the samples whose residual exceeds ``trim`` robust
    standard deviations (1.4826 MAD) - samples a learned segmentation put in the wrong region.

    Raises :class:`IdentificationError` when a region with a fitted model has no sample; warns
    :class:`RegionWarning` when a region has fewer samples than parameters (minimum-norm solution)
    or an ill-conditioned problem.
    """
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    labels = np.asarray(labels, dtype=np.int64)
    kinds = tuple(kinds) if kinds is not None else ("affine",) * n_regions
    if len(kinds) != n_regions:
        raise ParameterError(f"{len(kinds)} region model kinds for {n_regions} regions")
    for kind in kinds:
        if kind not in MODEL_KINDS:
            raise ParameterError(f"unknown region model kind {kind!r}; valid kinds are {list(MODEL_KINDS)}")
    if ridge < 0 or not np.isfinite(ridge):
        raise ParameterError(f"ridge must be a finite number >= 0, got {ridge!r}")
    nf = X.shape[1]
    theta = np.zeros((n_regions, nf + 1))
    counts = np.bincount(labels, minlength=n_regions)[:n_regions]
    cond = np.full(n_regions, np.nan)
    cov = np.full((n_regions, nf + 1, nf + 1), np.nan)
    n_par = nf + int(constant)
    for i, kind in enumerate(kinds):
        mask = labels == i
        if kind == "zero":
            cov[i] = 0.0
            continue
        if counts[i] == 0:
            raise IdentificationError(
                f"region {i + 1} is empty: no training sample falls in it, so its {kind} model "
                f"cannot be fitted; use fewer regions or move the hyperplanes"
            )
        if kind == "constant":
            theta[i, -1] = float(np.mean(y[mask]))
            cov[i] = 0.0
            cov[i, -1, -1] = float(np.var(y[mask], ddof=1)) / counts[i] if counts[i] > 1 else np.nan
            continue
        if warn and counts[i] < n_par:
            warnings.warn(RegionWarning(
                f"region {i + 1} has {counts[i]} samples for {n_par} parameters; its parameters are "
                f"the minimum-norm least-squares solution", "starved", region=i + 1, rows=int(counts[i]),
                parameters=n_par), stacklevel=2)
        Xi, yi = (X, y) if counts[i] == labels.size else (X[mask], y[mask])  # one region: no copy
        theta[i], cond[i], G, scale, mean = _fit_region(Xi, yi, constant, ridge)
        if trim is not None and counts[i] > 2 * n_par:
            r = yi - Xi @ theta[i, :-1] - theta[i, -1]
            sd = 1.4826 * np.median(np.abs(r - np.median(r)))
            keep = np.abs(r) <= trim * sd
            if sd > 0 and n_par < keep.sum() < keep.size:
                Xi, yi = Xi[keep], yi[keep]
                theta[i], cond[i], G, scale, mean = _fit_region(Xi, yi, constant, ridge)
        if G is None:  # a ridge or the SVD path: the plain normal matrix was not formed
            A, scale, mean = _scaled(Xi, constant)
            G = A.T @ A
        cov[i] = _covariance(Xi, yi, theta[i], constant, G, scale, mean)
        if warn and counts[i] >= n_par and cond[i] > ILL_CONDITIONED:
            warnings.warn(RegionWarning(
                f"region {i + 1}: least squares is ill-conditioned (condition number {cond[i]:.3g}); "
                f"its inputs may not be exciting enough, consider a ridge penalty",
                "ill_conditioned", region=i + 1, condition=float(cond[i])), stacklevel=2)
    return LocalModels(theta, kinds, counts.astype(np.int64), cond, cov)
