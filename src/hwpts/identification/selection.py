"""Model selection on the training data only: a grid of PWARX settings scored by free-run fit.

Each candidate (orders, segmentation, number of regions, partition columns, polish...) is fitted
on the data *before* a validation block and simulated in free run over that block, from measured
initial conditions (forward chaining: the blocks are the last ``n_folds`` slices of
``holdout * n`` samples). A candidate whose free run diverges on any block is rejected; the best
mean fit wins and is refitted on all the data. Candidates are independent (a map over the grid),
so the loop can run in processes or on a cluster without changes.
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


def _score_candidate(params, inputs, output, blocks):
    from hwpts.identification.pwarx import PWARX

    fits = []
    for start, stop in blocks:
        model = PWARX(**params)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model.fit(inputs[:start], output[:start])
            sim = model.simulate(inputs[start:stop], output[start:stop])
        if sim.diverged:
            return None, "free run diverged"
        m = model.structure_.max_lag
        fits.append(fit_percent(output[start + m:stop], sim.output[m:]))
    return fits, None


def select_model(inputs, output, grid: dict | list, base_params: dict | None = None, n_folds: int = 2,
                 holdout: float = 0.25, progress: bool = False):
    """Pick the PWARX settings with the best mean free-run fit on held-out blocks, refit on all.

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
    size = int(round(holdout * n))
    if size < 10 or n_folds < 1 or n - n_folds * size < size:
        raise ParameterError(f"select_model: {n} samples are too few for {n_folds} blocks of {holdout:.0%}")
    blocks = [(n - (n_folds - i) * size, n - (n_folds - i - 1) * size) for i in range(n_folds)]
    iterator = candidates
    if progress:
        from tqdm import tqdm

        iterator = tqdm(candidates, desc="selecting", disable=None)
    table = []
    for cand in iterator:
        params = {**(base_params or {}), **cand}
        row = {"params": cand, "fits": None, "mean_fit_percent": None, "rejected": None}
        try:
            fits, reason = _score_candidate(params, u, y, blocks)
        except HwptsError as error:
            fits, reason = None, f"fit failed: {error}"
        if fits is None:
            row["rejected"] = reason
        else:
            row["fits"] = [round(f, 3) for f in fits]
            row["mean_fit_percent"] = float(np.mean(fits))
        table.append(row)
    ok = [r for r in table if r["rejected"] is None]
    if not ok:
        raise IdentificationError("select_model: every candidate diverged in free run or failed")
    best = max(ok, key=lambda r: r["mean_fit_percent"])
    best["chosen"] = True
    model = PWARX(**{**(base_params or {}), **best["params"]})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model.fit(u, y)
    return model, table
