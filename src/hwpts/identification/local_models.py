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
    """``(A, scale)``: the regressors ``[X 1]`` divided by each column's root mean square (1 for a
    zero column)."""
    n = X.shape[0]
    Phi = np.hstack([X, np.ones((n, 1))]) if constant else X
    scale = np.sqrt(np.mean(Phi**2, axis=0)) if n else np.ones(Phi.shape[1])
    scale[scale == 0] = 1.0
    return Phi / scale, scale


def _fit_region(X: np.ndarray, y: np.ndarray, constant: bool, ridge: float = 0.0):
    """``(theta, cond, G, scale)``: least squares of one region (:func:`solve_region`), with the
    column-scaled normal matrix ``G = A' A`` that :func:`parameter_covariance` needs (``None``
    when it was not formed: a ridge, or the SVD path), so that it is not formed twice."""
    n, nf = X.shape
    A, scale = _scaled(X, constant)
    b = y
    if ridge > 0:
        pen = np.sqrt(ridge * max(n, 1)) * np.eye(A.shape[1])
        if constant:
            pen = pen[:-1]
        A = np.vstack([A, pen])
        b = np.concatenate([y, np.zeros(pen.shape[0])])
    coef = G = None
    if A.shape[0] >= 4 * A.shape[1]:  # tall: normal equations (fast), if well conditioned
        G = A.T @ A
        ev = np.linalg.eigvalsh(G)
        cond = float(np.sqrt(ev[-1] / ev[0])) if ev[0] > 0 else float("inf")
        if cond < 1e6:
            coef = np.linalg.solve(G, A.T @ b)
    if coef is None:  # SVD least squares: robust to rank deficiency
        coef, _, rank, sv = np.linalg.lstsq(A, b, rcond=None)
        cond = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    coef = coef / scale
    theta = np.zeros(nf + 1)
    if constant:
        theta[:] = coef
    else:
        theta[:nf] = coef
    return theta, cond, (G if ridge == 0 else None), scale


def solve_region(X: np.ndarray, y: np.ndarray, constant: bool, ridge: float = 0.0) -> tuple[np.ndarray, float]:
    """Least squares (eq. 17) of one region on column-scaled regressors; returns (theta, cond)."""
    theta, cond, _, _ = _fit_region(X, y, constant, ridge)
    return theta, cond


def parameter_covariance(X: np.ndarray, y: np.ndarray, theta: np.ndarray, constant: bool) -> np.ndarray:
    """Covariance ``sigma^2 (Phi' Phi)^-1`` of one region's least-squares parameters (eq. 17).

    ``sigma^2 = RSS / (n - p)``, the residual variance with ``p`` parameters; the matrix is over
    ``[x' 1]`` (offset last; its row and column are zero without a constant term). ``nan`` when the
    region has no more samples than parameters.
    """
    A, scale = _scaled(np.asarray(X, dtype=float), constant)
    return _covariance(X, y, theta, constant, A.T @ A, scale)


def _covariance(X, y, theta, constant, G, scale) -> np.ndarray:
    """:func:`parameter_covariance` from the column-scaled normal matrix ``G`` already formed."""
    n, nf = X.shape
    cov = np.full((nf + 1, nf + 1), np.nan)
    p = nf + int(constant)
    if n <= p:
        return cov
    r = y - X @ theta[:nf] - theta[nf]
    sigma2 = float(r @ r) / (n - p)
    inv = np.linalg.pinv(G) / np.outer(scale, scale)
    if constant:
        cov[:] = sigma2 * inv
    else:
        cov[:] = 0.0
        cov[:nf, :nf] = sigma2 * inv
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
        theta[i], cond[i], G, scale = _fit_region(Xi, yi, constant, ridge)
        if trim is not None and counts[i] > 2 * n_par:
            r = yi - Xi @ theta[i, :-1] - theta[i, -1]
            sd = 1.4826 * np.median(np.abs(r - np.median(r)))
            keep = np.abs(r) <= trim * sd
            if sd > 0 and n_par < keep.sum() < keep.size:
                Xi, yi = Xi[keep], yi[keep]
                theta[i], cond[i], G, scale = _fit_region(Xi, yi, constant, ridge)
        if G is None:  # a ridge or the SVD path: the plain normal matrix was not formed
            A, scale = _scaled(Xi, constant)
            G = A.T @ A
        cov[i] = _covariance(Xi, yi, theta[i], constant, G, scale)
        if warn and counts[i] >= n_par and cond[i] > ILL_CONDITIONED:
            warnings.warn(RegionWarning(
                f"region {i + 1}: least squares is ill-conditioned (condition number {cond[i]:.3g}); "
                f"its inputs may not be exciting enough, consider a ridge penalty",
                "ill_conditioned", region=i + 1, condition=float(cond[i])), stacklevel=2)
    return LocalModels(theta, kinds, counts.astype(np.int64), cond, cov)
