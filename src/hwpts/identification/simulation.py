"""Free-run simulation of a PWARX model with its switching rule (paper eqs. 5, 8, 10).

At each step the regressor ``x_k`` (eq. 7) is built from the model's *own* past outputs and the
measured inputs, its region ``sigma(k)`` is found in the polyhedral partition (eq. 9, first region
whose inequalities hold), and ``y_k = phi_k' theta_sigma(k)`` (eq. 5). The first ``max_lag`` outputs
are the measured ones (initial conditions). The loop is compiled with numba.

A run whose output leaves a wide band around the training range (or becomes non-finite) stops
and is reported as diverged: the fit of a diverged run is not a number, never ``-1e38``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from hwpts.dataset import dense_real
from hwpts.errors import DataError

__all__ = ["SimulationResult", "simulate_pwarx", "one_step_pwarx", "free_run_sensitivity"]


@dataclass(frozen=True)
class SimulationResult:
    """Result of a free-run simulation.

    Attributes
    ----------
    output : ndarray, shape (n,)
        Simulated output; the first ``n_initial`` samples are the measured initial conditions;
        after a divergence the remaining samples are ``nan``.
    regions : ndarray of int, shape (n,)
        Active region (0-based) per sample, ``-1`` for the initial conditions and after divergence.
    n_initial : int
    diverged : bool
    diverged_at : int or None
        First sample whose output left the band ``|y - center| <= bound``.
    reason : str or None
    """

    output: np.ndarray
    regions: np.ndarray
    n_initial: int
    diverged: bool = False
    diverged_at: int | None = None
    reason: str | None = None

    def score(self, measured, spread=None) -> float:
        """Free-run fit % (NRMSE) against the ``measured`` output after the initial conditions;
        ``nan`` when the run diverged (the one encoding of "diverged" in the package). With
        ``spread`` (the standard deviation of a whole record this is a block of), a model search's
        held-out score (:func:`~hwpts.identification.metrics.held_out_fit`: a block where the
        output rests is measured against that spread)."""
        from hwpts.identification.metrics import fit_percent, held_out_fit

        y = dense_real(measured, "measured")
        if y.ndim == 2 and y.shape[1] == 1:
            y = y[:, 0]
        if y.ndim != 1:
            raise DataError(f"measured must be the output, shape (n,) or (n, 1); got shape {y.shape}")
        if self.diverged:
            return float("nan")
        m = self.n_initial
        if y.shape[0] - m < 2:  # said as the signal being empty or constant before
            raise DataError(f"a fit % needs at least 2 samples after the {m} initial conditions, got "
                            f"{max(y.shape[0] - m, 0)}")
        if spread is not None:
            return held_out_fit(y[m:], self.output[m:], spread)
        return fit_percent(y[m:], self.output[m:])


@numba.njit(cache=True, nogil=True)
def _simulate_kernel(u, y0, n_init, sig, lag, pw, pc, ps, theta, H, g, row_start, center,
                     bound):  # pragma: no cover - compiled
    n = u.shape[0]
    nf = sig.shape[0]
    s = theta.shape[0]
    yhat = np.full(n, np.nan)
    regions = np.full(n, -1, dtype=np.int64)
    for k in range(n_init):
        yhat[k] = y0[k]
    x = np.empty(nf)
    for k in range(n_init, n):
        for c in range(nf):
            if sig[c] < 0:
                v = yhat[k - lag[c]]
            else:
                v = u[k - lag[c], sig[c]]
            if pw[c] != 1:  # a power term of the standardised output
                v = ((v - pc) / ps) ** pw[c]
            x[c] = v
        chosen = -1
        best = 0
        best_v = np.inf
        for r in range(s):
            mv = -np.inf
            for q in range(row_start[r], row_start[r + 1]):
                v = g[q]
                for c in range(nf):
                    v += H[q, c] * x[c]
                if v > mv:
                    mv = v
            if mv <= 0.0:
                chosen = r
                break
            if mv < best_v:
                best_v = mv
                best = r
        if chosen < 0:
            chosen = best
        val = theta[chosen, nf]
        for c in range(nf):
            val += theta[chosen, c] * x[c]
        if not (abs(val - center) <= bound):
            return yhat, regions, k
        yhat[k] = val
        regions[k] = chosen
    return yhat, regions, -1


@numba.njit(cache=True, nogil=True)
def _sensitivity_kernel(u, yhat, regions, n_init, stop, sig, lag, pw, pc, ps, theta):  # pragma: no cover - compiled
    n = u.shape[0]
    nf = sig.shape[0]
    q = nf + 1
    width = theta.shape[0] * q
    J = np.zeros((n, width))
    for k in range(n_init, stop):
        r = regions[k]
        base = r * q
        for c in range(nf):
            if sig[c] < 0:
                v = yhat[k - lag[c]]
            else:
                v = u[k - lag[c], sig[c]]
            if pw[c] != 1:
                v = ((v - pc) / ps) ** pw[c]
            J[k, base + c] = v
        J[k, base + nf] = 1.0
        for c in range(nf):  # the chain through the model's own past outputs
            if sig[c] < 0 and k - lag[c] >= n_init:
                a = theta[r, c]
                if pw[c] != 1:  # d/dy ((y - c) / s)^p = p ((y - c) / s)^(p - 1) / s
                    a *= pw[c] * ((yhat[k - lag[c]] - pc) / ps) ** (pw[c] - 1) / ps
                if a != 0.0:
                    kk = k - lag[c]
                    for j in range(width):
                        J[k, j] += a * J[kk, j]
    return J


def free_run_sensitivity(structure, theta, inputs, sim: SimulationResult) -> np.ndarray:
    """Jacobian of the free-run output ``sim.output`` with respect to ``theta`` (flattened row by
    row, shape ``(n, s * (n_features + 1))``), the regions held at those of the run.

    The sensitivity recursion of an output-error model (Ljung 1999, section 10.3): with
    ``yhat_k = phi_k' theta_r(k)``, ``d yhat_k / d theta = e_r(k) (x) phi_k + sum_i a_r(k),i
    d yhat_(k-i) / d theta`` over the autoregressive lags ``i``. The switching rule is piecewise
    constant in theta, so this is the derivative wherever it exists. Rows of the initial
    conditions, and from a divergence on, are zero."""
    u = np.ascontiguousarray(inputs, dtype=float)
    if u.ndim == 1:
        u = u[:, None]
    sig, lag = structure.lags
    stop = u.shape[0] if not sim.diverged else int(sim.diverged_at)
    return _sensitivity_kernel(u, np.ascontiguousarray(sim.output, dtype=float), np.ascontiguousarray(sim.regions),
                               min(sim.n_initial, u.shape[0]), stop, sig, lag, *_power_args(structure),
                               np.ascontiguousarray(theta, dtype=float))


def _power_args(structure) -> tuple:
    """``(pw, pc, ps)`` of the kernels: each column's power (1: a lagged signal), the power terms'
    center and scale."""
    return structure.powers, float(structure.power_center), float(structure.power_scale)


def simulate_pwarx(structure, partition, theta, inputs, initial_output, center=0.0, bound=np.inf) -> SimulationResult:
    """Free-run simulation (see module doc). ``initial_output`` holds at least ``max_lag`` samples."""
    u = np.ascontiguousarray(inputs, dtype=float)
    if u.ndim == 1:
        u = u[:, None]
    n = u.shape[0]
    m = structure.max_lag
    y0 = np.zeros(m)
    init = np.asarray(initial_output, dtype=float).ravel()[:m]
    y0[:init.size] = init  # a record shorter than max_lag is all initial conditions (the kernel reads n of them)
    sig, lag = structure.lags
    H, g, row_start = partition.flat()
    yhat, regions, k = _simulate_kernel(
        u, y0, min(m, n), sig, lag, *_power_args(structure), np.ascontiguousarray(theta, dtype=float), H, g, row_start,
        float(center), float(bound),
    )
    if k >= 0:
        return SimulationResult(
            yhat, regions, m, True, int(k),
            f"the free-run output left the band {center:.6g} +- {bound:.6g} at sample {k} "
            f"(the switched dynamics are unstable on this input, or it drives the model far outside the "
            f"range it was identified on)",
        )
    return SimulationResult(yhat, regions, m)


def one_step_pwarx(structure, partition, theta, inputs, output) -> tuple[np.ndarray, np.ndarray]:
    """One-step-ahead prediction from measured outputs: (yhat, regions), first max_lag measured/-1.
    A prediction that overflows (output power terms of data far beyond the training range) is
    inf or nan, without numpy's warnings: the caller says what it means."""
    with np.errstate(over="ignore", invalid="ignore"):
        X, _ = structure.build(inputs, output, fit=False)
        regions = partition.predict(X)
        th = np.asarray(theta)[regions]
        pred = np.einsum("ij,ij->i", X, th[:, :-1]) + th[:, -1]
    m = structure.max_lag
    y = np.asarray(output, dtype=float)
    yhat = np.concatenate([y[:m], pred])
    reg = np.concatenate([np.full(m, -1, dtype=np.int64), regions])
    return yhat, reg


def k_step_pwarx(structure, partition, theta, inputs, output, horizon: int,
                 center: float = 0.0, bound: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """k-step-ahead prediction ``yhat(t | t-k)``: (yhat, regions), the first max_lag measured/-1.

    ``yhat(t | t-k)`` is the free run (eqs. 5, 8, 10) started at ``s = t-k+1`` from the measured
    outputs before ``s`` and the measured inputs; where ``s`` would fall inside the initial
    conditions the run starts after them. ``horizon=1`` is the one-step prediction; a horizon of
    at least ``n - max_lag`` is the free run from the first ``max_lag`` samples.

    Computed for every ``t`` at once, step by step: with ``Q_j(t)`` the ``j``-step prediction,
    the regressor of ``Q_j(t)`` holds ``Q_{j-i}(t-i)`` for output lags ``i < j`` (the same run)
    and measured outputs for ``i >= j``; cost ``O(k n)``. A prediction outside the band
    ``|y - center| <= bound`` is ``nan`` (the run diverged).
    """
    y = np.asarray(output, dtype=float)
    n = y.shape[0]
    m = structure.max_lag
    if horizon <= 1:
        return one_step_pwarx(structure, partition, theta, inputs, y)
    if horizon >= n - m:  # every start falls at the initial conditions: the free run
        sim = simulate_pwarx(structure, partition, theta, inputs, y, center, bound)
        return sim.output, sim.regions
    X, _ = structure.build(inputs, y, fit=False)
    na = structure.na
    th = np.asarray(theta, dtype=float)
    t = np.arange(m, n)
    history: list[np.ndarray] = []  # history[i-1] = Q_{j-i} over all times (measured before m)
    regions = None
    for j in range(1, horizon + 1):
        Xj = X
        if na and history:
            Xj = X.copy()
            for i in range(1, min(na, j - 1) + 1):
                Xj[:, i - 1] = history[i - 1][t - i]
            structure.with_powers(Xj)  # the power terms of the predicted y(k-1)
        regions = partition.predict(Xj)
        sel = th[regions]
        pred = np.einsum("ij,ij->i", Xj, sel[:, :-1]) + sel[:, -1]
        pred[~(np.abs(pred - center) <= bound)] = np.nan
        q = np.concatenate([y[:m], pred])
        if na:
            history.insert(0, q)
            del history[na:]
        if not na:  # no output in the regressor: every horizon is the one-step prediction
            break
    reg = np.concatenate([np.full(m, -1, dtype=np.int64), regions])
    return q, reg
