"""Run PyPARC (Bemporad's piecewise affine regression) on lagged regressors; print JSON.

Executed by ``benchmarks/bench_identification.py`` with the interpreter of ``benchmarks/.venv-pyparc``
(PyPARC installs only with pins). Usage::

    python pyparc_runner.py DATA.npz K SIGMA

DATA.npz holds X_train, y_train (regressors y(k-1), y(k-2), u1(k-1), u1(k-2), u2(k-1), u2(k-2))
and u_val, y_val (validation inputs/outputs for the free run). PyPARC is a static regressor: the
free-run loop below builds each regressor from the simulated outputs and calls ``predict`` on it.
"""

import json
import sys
import time

import numpy as np


def main(argv):
    path, K, sigma = argv[0], int(argv[1]), float(argv[2])
    from pyparc.parc import PARC

    data = np.load(path)
    X, y = data["X_train"], data["y_train"]
    u, yv = data["u_val"], data["y_val"]
    model = PARC(K=K, alpha=1.0e-4, sigma=sigma, separation="Softmax", maxiter=15, cost_tol=1e-4,
                 min_number=10, fit_on_partition=True, beta=1.0e-3, verbose=0)
    t0 = time.perf_counter()
    model.fit(X, y)
    fit_time = time.perf_counter() - t0
    n = yv.shape[0]
    yhat = np.zeros(n)
    yhat[:2] = yv[:2]
    modes = np.full(n, -1)
    t0 = time.perf_counter()
    for k in range(2, n):
        x = np.array([[yhat[k - 1], yhat[k - 2], u[k - 1, 0], u[k - 2, 0], u[k - 1, 1], u[k - 2, 1]]])
        pred, delta = model.predict(x)
        yhat[k] = float(np.ravel(pred)[0])
        modes[k] = int(np.ravel(delta)[0])
        if not np.isfinite(yhat[k]) or abs(yhat[k]) > 1e6:
            break
    sim_time = time.perf_counter() - t0
    ok = np.all(np.isfinite(yhat)) and np.max(np.abs(yhat)) < 1e6
    fit = (100 * (1 - np.linalg.norm(yv[2:] - yhat[2:]) / np.linalg.norm(yv[2:] - yv[2:].mean()))) if ok else None
    print(json.dumps({"fit_time_s": fit_time, "sim_time_s": sim_time, "fit_percent": fit,
                      "modes": modes[2:].tolist()}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
