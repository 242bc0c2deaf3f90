"""Run PyPARC on regressor rows and predict one step ahead on validation regressor rows.

Executed by ``benchmarks/bench_zoo.py`` with the interpreter of ``benchmarks/.venv-pyparc``.
Usage::

    python pyparc_zoo_runner.py DATA.npz K OUT.npz [SEED]

DATA.npz holds X_train, y_train (training regressor rows and targets) and X_val (validation
regressor rows built from measured outputs). OUT.npz receives ``yhat`` and ``regions`` for X_val;
the fit time is printed as JSON. PyPARC is told the true number of regions ``K``; its other
settings are those of its own examples (alpha 1e-4, sigma 1, softmax separation, 15 iterations).
SEED seeds numpy's global generator, which PyPARC's k-means start draws from (it passes no
``random_state``): unseeded, its column of the zoo table moved by up to 2 points between runs.
"""

import json
import sys
import time

import numpy as np


def main(argv):
    path, K, out = argv[0], int(argv[1]), argv[2]
    from pyparc.parc import PARC

    if len(argv) > 3:
        np.random.seed(int(argv[3]))
    data = np.load(path)
    X, y, Xv = data["X_train"], data["y_train"], data["X_val"]
    model = PARC(K=K, alpha=1.0e-4, sigma=1.0, separation="Softmax", maxiter=15, cost_tol=1e-4,
                 min_number=min(10, max(1, X.shape[0] // (3 * K))), fit_on_partition=True,
                 beta=1.0e-3, verbose=0)
    t0 = time.perf_counter()
    model.fit(X, y)
    fit_time = time.perf_counter() - t0
    pred, delta = model.predict(Xv)
    np.savez(out, yhat=np.ravel(pred).astype(float), regions=np.ravel(delta).astype(int))
    print(json.dumps({"fit_time_s": fit_time}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
