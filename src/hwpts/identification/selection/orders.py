"""A model-free ranking of the orders: the held-out one-step fit of a nearest-neighbour predictor.

The adaptive search ranks the orders by the held-out fit of a single ARX model each. Where the
data are far from linear no ARX model explains them, and the ARX ranking is noise: on a three-mode
system behind oblique boundaries (``python -m benchmarks unseen``, ``oblique_3``, true orders
na 1, nb 1, nk 1) the 40 orders' held-out free-run fits lay within 0.1 point of each other on
each seed (17.8-20.4 % over the three seeds), and the search carried 3/3/1, 3/2/0 and 1/3/1.

A k-nearest-neighbour regressor on the standardised regressors (distance-weighted, as
scikit-learn's ``KNeighborsRegressor(weights="distance")``, on scipy's k-d tree) needs no model of
the map, so its held-out one-step fit ranks the orders by how well the past they contain *determines* the next output: a missing lag leaves the output
undetermined, a superfluous one spreads the neighbours (the idea of the nonparametric order tests
of He & Asada's Lipschitz quotients, 1993, and of false nearest neighbours). On ``oblique_3`` it
ranks the true orders first on every seed (80.9-83.1 % against 71-75 % for the next), and on the
other unseen systems the true orders are among its first three.

Where a linear model explains the data the neighbours are the worse predictor (on the four real
records 58.4-99.3 % against ARX's 90.1-100 %: interpolating between neighbours in 5-9 dimensions is
coarse next to a linear fit) and their ranking says little; the search uses it only where it
predicts far better than every ARX model (:data:`hwpts.identification.selection.search.NEIGHBOUR_GATE`).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from hwpts.errors import ParameterError
from hwpts.identification.metrics import held_out_fit, output_spread
from hwpts.identification.regressors import RegressorStructure

__all__ = ["neighbour_fits", "estimate_delays", "delay_candidates"]

N_NEIGHBOURS = 5
MAX_TRAIN_ROWS = 3000  # rows of a training part the neighbours are drawn from (seeded subsample)
MAX_TEST_ROWS = 1000  # rows of a held-out block predicted


def _inside(mask: np.ndarray, max_lag: int) -> np.ndarray:
    """For each regressor row (target index ``max_lag + r``): whether its whole lag window
    ``[k - max_lag, k]`` lies where ``mask`` is true."""
    counts = np.concatenate([[0], np.cumsum(mask.astype(np.int64))])
    k = np.arange(max_lag, mask.size)
    return counts[k + 1] - counts[k - max_lag] == max_lag + 1


def _predict(X, t, Xq, k):
    """Distance-weighted k-nearest-neighbour prediction at ``Xq`` (as scikit-learn's
    ``KNeighborsRegressor(k, weights="distance")``: an exact match takes its target; where
    distances tie at the k-th neighbour the two may pick different neighbours), with scipy's
    k-d tree, without the estimator's per-call validation (200 fits a search on 40 orders)."""
    dist, idx = cKDTree(X).query(Xq, k=k)
    dist, idx = dist.reshape(len(Xq), -1), idx.reshape(len(Xq), -1)
    exact = dist[:, 0] <= 0.0
    with np.errstate(divide="ignore"):
        w = 1.0 / dist
    w[exact] = (dist[exact] <= 0.0).astype(float)
    return np.sum(w * t[idx], axis=1) / np.sum(w, axis=1)


def neighbour_fits(u, y, orders, splits, *, n_neighbors: int = N_NEIGHBOURS, random_state=0) -> list[float]:
    """Mean held-out one-step fit % (:func:`~hwpts.identification.metrics.held_out_fit`) of a
    nearest-neighbour predictor for each ``(na, nb, nk)`` in
    ``orders``, over the ``(train, test)`` sample-index pairs of ``splits``.

    A regressor row belongs to a part when its whole lag window does (no row mixes a training part
    with a held-out block, nor the two sides of a gap in a training part). The regressors are
    standardised on the training rows; at most :data:`MAX_TRAIN_ROWS` training rows and
    :data:`MAX_TEST_ROWS` held-out rows are used (a draw seeded by ``random_state``). ``nan`` for
    an order whose parts hold too few rows, or whose regressor cannot be built (na = nb = 0).
    """
    u = np.asarray(u, dtype=float)
    u = u[:, None] if u.ndim == 1 else u
    y = np.asarray(y, dtype=float)
    n = y.size
    spread = output_spread(y)  # every block scored against the whole output's spread (held_out_fit)
    masks = []
    for train, test in splits:
        tr = np.zeros(n, bool)
        tr[np.asarray(train)] = True
        te = np.zeros(n, bool)
        te[np.asarray(test)] = True
        masks.append((tr, te))
    out = []
    for na, nb, nk in orders:
        try:
            structure = RegressorStructure.create(na, nb, nk, u.shape[1], True)
        except ParameterError:  # e.g. na = 0 with nb = 0: no regressor, nothing to rank
            out.append(float("nan"))
            continue
        m = structure.max_lag
        X, t = structure.build(u, y)
        fits = []
        for tr, te in masks:
            # a window that crosses a held-out block (the join of a blocked split's training part)
            # holds samples outside the training part: such rows are out
            rtr, rte = _inside(tr, m), _inside(te, m)
            itr, ite = np.flatnonzero(rtr), np.flatnonzero(rte)
            if itr.size <= n_neighbors or ite.size < 2:
                fits.append(np.nan)
                continue
            rng = np.random.default_rng(random_state)
            if itr.size > MAX_TRAIN_ROWS:
                itr = np.sort(rng.choice(itr, MAX_TRAIN_ROWS, replace=False))
            if ite.size > MAX_TEST_ROWS:
                ite = np.sort(rng.choice(ite, MAX_TEST_ROWS, replace=False))
            mean = X[itr].mean(axis=0)
            scale = X[itr].std(axis=0)
            scale[scale <= 0] = 1.0
            fits.append(held_out_fit(t[ite], _predict((X[itr] - mean) / scale, t[itr], (X[ite] - mean) / scale,
                                                      n_neighbors), spread))
        out.append(float(np.mean(fits)) if np.all(np.isfinite(fits)) else float("nan"))
    return out


MAX_DELAY = 20  # largest input delay estimate_delays tries (MATLAB's delayest: nkmin + 20)
DELAY_TOLERANCE = 0.1  # a delay above 1 must cut the ARX loss of delays 0-1 by this share ...
DELAY_CHANCE = 20.0  # ... and by DELAY_CHANCE / rows: what the best of 19 unrelated input windows
# cuts by chance is about (2 ln 19 + 2 nb) / rows (chi-square with nb degrees of freedom per window,
# the largest of 19); measured on a delay-1 system with a weak input (gain 0.3, unit noise), the flat
# 10 % alone read a delay above 1 on 80 of 200 records of 60 samples and 8 of 200 of 100 samples


def estimate_delays(u, y, *, max_delay: int = MAX_DELAY, na: int = 2, nb: int = 2,
                    tolerance: float = DELAY_TOLERANCE) -> tuple[int, ...]:
    """The input delay ``nk`` of each input, estimated as MATLAB's ``delayest`` does: an ARX model
    ``(na, nb, nk)`` of the output on that input is fitted by least squares for every ``nk`` from 0
    to ``max_delay`` (on the same rows), and the delay with the least residual sum of squares wins,
    but a delay above 1 only when its loss is more than ``tolerance`` (and :data:`DELAY_CHANCE`
    / rows) below the best of delays 0 and 1 (the orders grid's own; where the input barely moves
    the output the losses are flat and their argmin is noise). The largest delay tried is at most
    a tenth of the record and leaves at least ``5 (na + nb + 1)`` rows. Every sample is used,
    the search's held-out blocks included (one choice of two delay candidates, made before the
    cross-validation, as the grid itself is).

    The orders grid of :class:`~hwpts.identification.PWARXSearch` has delays 0 and 1 only; a plant
    with dead time (a transport delay sampled fast) needs more: on ``dead_time_5`` of
    ``python -m benchmarks unseen`` (two modes, a 5-sample delay) the search with the grid's delays
    scored 82.4 % median validation fit, with the estimate 95.9 % (told the orders 96.1 %).
    """
    u = np.asarray(u, dtype=float)
    u = u[:, None] if u.ndim == 1 else u
    y = np.asarray(y, dtype=float)
    n = y.size
    p = na + nb + 1
    # at most a tenth of the record (the search's blocks must still hold the lags), and at least
    # 5 p rows left
    top = int(min(max_delay, n // 10, n - 5 * p - nb + 1 - na))
    if top <= 1:
        return tuple(0 for _ in range(u.shape[1]))
    delays = []
    for j in range(u.shape[1]):
        # one regressor with every lag u(k) .. u(k - top - nb + 1): each delay's window is a slice
        # of it, on the same rows
        X, t = RegressorStructure.create(na, top + nb, 0, 1, False).build(u[:, j], y)
        past = np.column_stack([X[:, :na], np.ones(t.size)])
        losses = []
        for nk in range(top + 1):
            A = np.column_stack([past, X[:, na + nk:na + nk + nb]])
            theta = np.linalg.lstsq(A, t, rcond=None)[0]
            losses.append(float(np.sum((t - A @ theta) ** 2)))
        losses = np.asarray(losses)
        best = int(np.argmin(losses))
        near = int(np.argmin(losses[:2]))  # the delays of the orders grid's own (0 and 1)
        # a longer delay only on evidence: a loss clearly below the short delays' best, by more
        # than the best of the other windows would cut by chance (where the input barely moves
        # the output the losses are flat, and their argmin is noise)
        margin = max(tolerance, DELAY_CHANCE / t.size)
        delay = best if best >= 2 and losses[best] < (1.0 - margin) * losses[near] else near
        # the window of nb lags at ``delay`` and the one a sample later both hold u(k - d) when
        # the response starts at d = delay + 1: equal losses, so the argmin is a coin flip between
        # d - 1 and d (a pure delay of 2 read as 1 on 10 seeds of 10). The later window costing no
        # more than chance, and the one after it clearly more (the response's first lag has left
        # it; on a flat loss curve, where the input barely moves the output, nothing is shifted),
        # says the earlier window's first lag is not needed: the delay is one sample later.
        if delay + 2 <= top and losses[delay + 1] <= (1.0 + DELAY_CHANCE / t.size) * losses[delay] \
                and losses[delay + 2] > (1.0 + margin) * losses[delay + 1]:
            delay += 1
        delays.append(delay)
    return tuple(delays)


def delay_candidates(delays) -> list:
    """The ``input_delay`` values of an orders grid for estimated ``delays`` (one per input): the
    grid's own ``(1, 0)`` while no input's delay exceeds 1, else each estimate and one sample less
    (an int when every input has the same delay, else a list per input)."""
    delays = [int(d) for d in delays]
    if max(delays) <= 1:
        return [1, 0]
    lower = [max(d - 1, 0) for d in delays]
    if len(set(delays)) == 1:
        return [delays[0], lower[0]]
    return [delays, lower]
