"""Smooth nonlinearities of the output, the case the output power terms are for, on systems written
for this check (none is Silverbox's, none has a cubic of the kind the powers 2, 3 hold exactly but
the first):

| system | what it is |
|---|---|
| ``duffing_soft`` | a softening spring with an asymmetric term: ``y(k-1)^2`` and ``-y(k-1)^3`` terms of other signs and sizes than Silverbox's |
| ``tank_sqrt`` | a tank draining through an orifice: outflow ``sqrt(y)`` (not a polynomial), inflow from a pump ``u(k-1)`` |
| ``tanh_feedback`` | a second-order loop whose feedback saturates: ``tanh(2 y(k-1))`` (odd, not a polynomial) |

Each seed: 2,000 training samples with equation-error noise of 2 % of the noise-free output's
standard deviation, then two noise-free validation records from other input realisations: one of
the training amplitude, one 25 % larger (``extrapolation``: outputs beyond the training range).
Free-run fit % from the validation's first outputs, median [min, max] over the seeds, for the
default search (``PWARXSearch(PWARX(random_state=0), orders="auto")``), the same search without
the power terms (``output_powers=None``, the default before them) and one ARX model of the true
orders (the floor). No oracle: the systems are not PWARX.

``python -m benchmarks smooth [--seeds=N] [--systems=a,b]``
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

from benchmarks.bench_unseen import cell, chosen_label, seeds_and_systems

NOISE = 0.02
N_TRAIN, N_VALID = 2000, 3000
GROWTH = 1.25  # the extrapolation record's input amplitude, relative to the training one


def _duffing_soft(y, u, k):
    return 1.6 * y[k - 1] - 0.75 * y[k - 2] + 0.08 * y[k - 1] ** 2 - 0.06 * y[k - 1] ** 3 + 0.3 * u[k - 1]


def _tank_sqrt(y, u, k):
    return y[k - 1] - 0.1 * np.sqrt(max(y[k - 1], 0.0)) + 0.08 * u[k - 1]


def _tanh_feedback(y, u, k):
    return 1.2 * y[k - 1] - 0.45 * y[k - 2] - 0.4 * np.tanh(2.0 * y[k - 1]) + 0.5 * u[k - 1]


# name: (step, orders (na, nb, nk), input generator (rng, n, amplitude) -> u, initial output)
SYSTEMS = {
    "duffing_soft": (_duffing_soft, (2, 1, 1), lambda r, n, a: a * r.uniform(-1, 1, n), 0.0),
    "tank_sqrt": (_tank_sqrt, (1, 1, 1), lambda r, n, a: np.repeat(1.0 + a * r.uniform(-0.8, 0.8, n // 25 + 1), 25)[:n],
                  0.64),
    "tanh_feedback": (_tanh_feedback, (2, 1, 1), lambda r, n, a: a * r.uniform(-1, 1, n), 0.0),
}


def simulate(name, u, noise=None):
    step, (na, nb, nk), _, y0 = SYSTEMS[name]
    m = max(na, nb + nk - 1)
    y = np.full(u.shape[0], y0, dtype=float)
    for k in range(m, u.shape[0]):
        y[k] = step(y, u, k) + (0.0 if noise is None else noise[k])
    return y


def data(name, seed):
    """Training ``(u, y)`` and the validation records ``{"validation": (u, y), "extrapolation": (u, y)}``."""
    gen = SYSTEMS[name][2]
    rng = np.random.default_rng(seed)
    u = gen(rng, N_TRAIN, 1.0)
    clean = simulate(name, u)
    y = simulate(name, u, NOISE * np.std(clean) * rng.standard_normal(N_TRAIN))
    valid = {}
    for label, amp in (("validation", 1.0), ("extrapolation", GROWTH)):
        uv = gen(np.random.default_rng(10_000 + seed), N_VALID, amp)
        valid[label] = (uv[:, None], simulate(name, uv))
    return (u[:, None], y), valid


def run(name, seeds):
    from hwpts.identification import PWARX, PWARXSearch

    na, nb, nk = SYSTEMS[name][1]
    rows = {(k, v): [] for k in ("hwpts", "hwpts, no powers", "ARX") for v in ("validation", "extrapolation")}
    chosen, times, beyond = [], [], []
    for seed in seeds:
        (u, y), valid = data(name, seed)
        beyond.append(float(np.mean((valid["extrapolation"][1] > y.max()) | (valid["extrapolation"][1] < y.min()))))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t0 = time.perf_counter()
            search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, y)
            times.append(time.perf_counter() - t0)
            plain = PWARXSearch(PWARX(random_state=0), orders="auto", output_powers=None).fit(u, y)
            arx = PWARX(na, nb, nk, n_regions=1, segmentation="average").fit(u, y)
            for label, (uv, yv) in valid.items():
                for key, model in (("hwpts", search.best_estimator_), ("hwpts, no powers", plain.best_estimator_),
                                   ("ARX", arx)):
                    rows[key, label].append(model.simulate(uv, yv).score(yv))
        chosen.append(chosen_label(search.best_estimator_))
    return rows, chosen, times, beyond


def main(argv=None) -> int:
    parsed = seeds_and_systems(list(argv or []), SYSTEMS, "smooth")
    if parsed is None:
        return 2
    seeds, names = parsed
    n_seeds = len(seeds)
    print(f"free-run fit % on noise-free data, median [min, max] over {n_seeds} seed(s); {N_TRAIN} training "
          f"samples, noise {NOISE:.0%} of the output's std; extrapolation: inputs x{GROWTH}")

    print(f"{'system':15s} {'record':14s} {'hwpts':>23s} {'hwpts, no powers':>23s} {'ARX':>7s} {'search s':>8s}  "
          f"chosen (na/nb/nk method regions)")
    for name in names:
        rows, chosen, times, beyond = run(name, seeds)
        for label in ("validation", "extrapolation"):
            extra = (f"  ({100 * np.median(beyond):.0f} % of outputs beyond the training range)"
                     if label == "extrapolation" else f"{np.median(times):8.1f}  {'; '.join(chosen)}")
            print(f"{name:15s} {label:14s} {cell(rows['hwpts', label], 6):>23s} "
                  f"{cell(rows['hwpts, no powers', label], 6):>23s} "
                  f"{np.nanmedian(rows['ARX', label]):7.1f} {extra}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
