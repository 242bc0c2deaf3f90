"""Model selection on the training data only: a grid of PWARX settings scored by free-run fit.

Each candidate (orders, segmentation, number of regions, partition columns, polish...) is fitted
on part of the training data and simulated in free run over a held-out block, from measured
initial conditions. Two schemes:

- ``scheme="forward"`` (default, forward chaining): the blocks are the last ``n_folds`` slices of
  ``holdout * n`` samples, each candidate fitted on the data *before* the block. Only the end of
  the record is ever validated.
- ``scheme="blocked"`` (blocked cross-validation for time series, Bergmeir & Benitez 2012): the
  record is cut into ``n_folds`` contiguous blocks; for each block the candidate is fitted on the
  other blocks (the data before and after it, joined) and simulated in free run over the whole
  block. Every operating regime of the record is validated, each fold model sees
  ``(n_folds - 1) / n_folds`` of the data, and the mean over many long blocks is a lower-variance
  estimate of the free-run fit than a few blocks at the end; prefer it when the record visits its
  regimes unevenly in time. At the junction of the two sides, ``max_lag`` regressor rows mix samples
  from before and after the block (a negligible share of the rows; the learned partitions trim
  outlying rows).

A candidate whose free run diverges, or whose fit fails, on any block is rejected; the best mean
fit wins and is refitted on all the data; a refit that does much worse on the same blocks than
its fold models (a learned partition can land differently on all the data) is rejected in favour
of the next candidate. Candidates are independent (a map over the grid);
``n_jobs`` runs them in processes (joblib).
"""

from __future__ import annotations

import itertools
import warnings

import numpy as np

from hwpts.errors import HwptsError, IdentificationError, ParameterError
from hwpts.identification.metrics import fit_percent

__all__ = ["select_model", "expand_grid"]


def expand_grid(grid: dict) -> list[dict]:
    """All combinations of a dict of lists (like scikit-learn's ParameterGrid)."""
    keys = list(grid)
    return [dict(zip(keys, values)) for values in itertools.product(*(grid[k] for k in keys))]


SCHEMES = ("forward", "blocked")


def _score_candidate(params, inputs, output, blocks, scheme="forward"):
    """Free-run fit of ``params`` on each held-out block: (fits, None) or (None, why rejected)."""
    from hwpts.identification.pwarx import PWARX

    fits = []
    try:
        for start, stop in blocks:
            model = PWARX(**params)
            if scheme == "blocked":
                u_fit = np.concatenate([inputs[:start], inputs[stop:]])
                y_fit = np.concatenate([output[:start], output[stop:]])
            else:
                u_fit, y_fit = inputs[:start], output[:start]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model.fit(u_fit, y_fit)
                sim = model.simulate(inputs[start:stop], output[start:stop])
            if sim.diverged:
                return None, "free run diverged"
            m = model.structure_.max_lag
            fits.append(fit_percent(output[start + m:stop], sim.output[m:]))
    except HwptsError as error:
        return None, f"fit failed: {error}"
    return fits, None


def _row(cand, params, u, y, blocks, scheme):
    row = {"params": cand, "fits": None, "mean_fit_percent": None, "rejected": None}
    fits, row["rejected"] = _score_candidate(params, u, y, blocks, scheme)
    if fits is not None:
        row["fits"] = [round(f, 3) for f in fits]
        row["mean_fit_percent"] = float(np.mean(fits))
    return row


def select_model(inputs, output, grid: dict | list, base_params: dict | None = None, n_folds: int = 2,
                 holdout: float = 0.25, progress: bool = False, scheme: str = "forward",
                 n_jobs: int | None = None, refit_margin: float = 5.0):
    """Pick the PWARX settings with the best mean free-run fit on held-out blocks, refit on all.

    ``scheme``: ``"forward"`` (the last ``n_folds`` blocks of ``holdout * n`` samples, fitted on
    the data before each) or ``"blocked"`` (``n_folds`` contiguous blocks covering the record,
    fitted on the others; ``holdout`` is ignored). ``n_jobs``: candidates in parallel processes
    (joblib; ``None`` or 1 = sequential, same results either way). ``refit_margin``: the refit on
    all data must score, on the same blocks, at least the cross-validated mean minus this many
    points, or the next candidate is tried (the table row says why it was rejected).

    Returns ``(model, table)``: the refitted estimator and one row per candidate (its parameters,
    per-block fits, mean, or why it was rejected).
    """
    from hwpts.identification.pwarx import PWARX
    from hwpts.identification.regressors import validate_signals

    u, y = validate_signals(inputs, output)
    candidates = grid if isinstance(grid, list) else expand_grid(grid)
    if not candidates:
        raise ParameterError("select_model: empty grid")
    n = y.shape[0]
    if scheme not in SCHEMES:
        raise ParameterError(f"select_model: unknown scheme {scheme!r}; valid are {list(SCHEMES)}")
    if scheme == "blocked":
        if not isinstance(n_folds, (int, np.integer)) or n_folds < 2 or n // n_folds < 10:
            raise ParameterError(f"select_model: {n} samples cannot make {n_folds} blocks (need >= 2 of >= 10)")
        edges = np.linspace(0, n, n_folds + 1).round().astype(int)
        blocks = [(int(edges[i]), int(edges[i + 1])) for i in range(n_folds)]
    else:
        size = int(round(holdout * n))
        if size < 10 or n_folds < 1 or n - n_folds * size < size:
            raise ParameterError(f"select_model: {n} samples are too few for {n_folds} blocks of {holdout:.0%}")
        blocks = [(n - (n_folds - i) * size, n - (n_folds - i - 1) * size) for i in range(n_folds)]
    jobs = [(cand, {**(base_params or {}), **cand}) for cand in candidates]
    if n_jobs not in (None, 1):
        from joblib import Parallel, delayed

        table = Parallel(n_jobs=n_jobs)(delayed(_row)(c, p, u, y, blocks, scheme) for c, p in jobs)
    else:
        iterator = jobs
        if progress:
            from tqdm import tqdm

            iterator = tqdm(jobs, desc="selecting", disable=None)
        table = [_row(c, p, u, y, blocks, scheme) for c, p in iterator]
    ok = [r for r in table if r["rejected"] is None]
    if not ok:
        raise IdentificationError("select_model: every candidate diverged in free run or failed")
    # Refit the best candidate on all the data and check the refitted model on the same blocks
    # (in-sample now, so it should do at least as well as its fold models): a refit that falls more
    # than ``refit_margin`` points below the cross-validated mean, diverges or fails (e.g. a
    # learned partition that lands on a starved, unstable region) is rejected and the next best
    # candidate is refitted instead.
    for best in sorted(ok, key=lambda r: -r["mean_fit_percent"]):
        model = PWARX(**{**(base_params or {}), **best["params"]})
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model.fit(u, y)
                refit = []
                for start, stop in blocks:
                    sim = model.simulate(u[start:stop], y[start:stop])
                    m = model.structure_.max_lag
                    refit.append(-np.inf if sim.diverged else fit_percent(y[start + m:stop], sim.output[m:]))
        except HwptsError as error:
            best["rejected"] = f"refit on all data failed: {error}"
            continue
        best["refit_fit_percent"] = float(np.mean(refit))
        if best["refit_fit_percent"] >= best["mean_fit_percent"] - refit_margin:
            best["chosen"] = True
            return model, table
        best["rejected"] = (f"refit on all data: block fit {best['refit_fit_percent']:.1f} % is more than "
                            f"{refit_margin} points below the cross-validated {best['mean_fit_percent']:.1f} %")
    raise IdentificationError("select_model: every candidate's refit on all data failed its check")
