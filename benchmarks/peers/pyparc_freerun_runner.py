"""Fit PyPARC on ARX regressors and simulate it in free run on a test record; print JSON.

Executed by ``benchmarks/bench_real.py`` with the interpreter of ``benchmarks/.venv-pyparc``.
Usage::

    python pyparc_freerun_runner.py DATA.npz K OUT.npz [SEED]

DATA.npz holds u_train, y_train, u_test, y_test (one input) and orders na, nb, nk, n_init. The
regressor is [y(k-1..k-na), u(k-nk..k-nk-nb+1)]; the free run builds it from its own outputs and
starts from the first ``n_init`` measured outputs. OUT.npz receives the simulated output; OUT ``-``
fits only (a timing run). SEED seeds numpy's global generator, which PyPARC's k-means start draws
from (it passes no ``random_state``): unseeded, its fit time on Silverbox ranged 3.9-15.8 s between
runs on the same data.
"""

import json
import sys
import time

import numpy as np


def regressors(u, y, na, nb, nk):
    m = max(na, nk + nb - 1)
    rows = [[y[k - i] for i in range(1, na + 1)] + [u[k - nk - j] for j in range(nb)] for k in range(m, len(y))]
    return np.array(rows), y[m:], m


def main(argv):
    path, K, out = argv[0], int(argv[1]), argv[2]
    from pyparc.parc import PARC

    if len(argv) > 3:
        np.random.seed(int(argv[3]))

    d = np.load(path)
    na, nb, nk, n_init = (int(d[k]) for k in ("na", "nb", "nk", "n_init"))
    X, y, m = regressors(d["u_train"], d["y_train"], na, nb, nk)
    model = PARC(K=K, alpha=1.0e-4, sigma=1.0, separation="Softmax", maxiter=15, cost_tol=1e-4,
                 min_number=10, fit_on_partition=True, beta=1.0e-3, verbose=0)
    t0 = time.perf_counter()
    model.fit(X, y)
    fit_time = time.perf_counter() - t0
    if out == "-":
        print(json.dumps({"fit_time_s": fit_time}))
        return 0
    u, yt = d["u_test"], d["y_test"]
    n0 = max(n_init, m)
    yhat = np.array(yt, dtype=float)
    yhat[n0:] = np.nan
    t0 = time.perf_counter()
    for k in range(n0, len(yt)):
        x = [yhat[k - i] for i in range(1, na + 1)] + [u[k - nk - j] for j in range(nb)]
        pred, _ = model.predict(np.array([x]))
        yhat[k] = float(np.ravel(pred)[0])
        if not np.isfinite(yhat[k]) or abs(yhat[k]) > 1e6:
            break
    np.savez(out, yhat=yhat)
    print(json.dumps({"fit_time_s": fit_time, "sim_time_s": time.perf_counter() - t0}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
