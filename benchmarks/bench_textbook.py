"""Textbook plants the default search was not built for: piecewise maps written as simulations,
not as PWARX systems, each with what makes it hard.

| system | plant |
|---|---|
| ``integrator_sat`` | a tank that empties and overflows: ``y(k) = min(10, max(0, y(k-1) + 0.2 u(k-1)))`` (a continuous PWA map, oblique boundaries) |
| ``deadzone_hammerstein`` | a second-order linear plant behind an input dead zone of +-0.3 |
| ``offset_1e4`` | two modes switching on ``y(k-1) - 1e4``: the output sits around 1e4 |
| ``irrelevant_u2`` | two modes switching on ``u1(k-1)``; a second input that does nothing |
| ``coloured_noise`` | two modes switching on ``y(k-1)``, the noise filtered by ``1 / (1 - 0.9 q^-1)`` |
| ``oversampled`` | two first-order modes with poles 0.995 and 0.98, the input held 200 samples |

Each seed: 300 and 3,000 training samples with noise of 3 % of the noise-free output's standard
deviation (equation error), 3,000 noise-free validation samples from another input realisation,
free run from the validation's first outputs. Columns: the default search (orders chosen), the same
search told the plant's orders, one ARX model of those orders (``nan``: its free run diverged),
the search's time and choice.

``python -m benchmarks textbook [--seeds=N] [--systems=a,b]`` (1 seed by default);
``--methods [--seeds=5] [--samples=N]``: the tank's segmentation methods side by side on N
training samples (3,000; :func:`tank_methods`).
"""

from __future__ import annotations

import warnings

import numpy as np

from benchmarks.bench_unseen import cell, chosen_label, free_fit, seeds_and_systems, three_fits

NOISE = 0.03  # noise standard deviation, as a share of the noise-free output's
SIZES = (300, 3000)
N_VALID = 3000


def _held(rng, n, low, high, hold, n_inputs=1):
    """Inputs drawn uniformly in ``[low, high]`` and held ``hold`` samples."""
    v = rng.uniform(low, high, (n // hold + 1, n_inputs))
    return np.repeat(v, hold, axis=0)[:n]


def _dead_zone(v):
    return np.sign(v) * max(abs(v) - 0.3, 0.0)


def _integrator_sat(y, u, k):
    return min(10.0, max(0.0, y[k - 1] + 0.2 * u[k - 1, 0]))


def _deadzone_hammerstein(y, u, k):
    return 1.5 * y[k - 1] - 0.7 * y[k - 2] + 0.5 * _dead_zone(u[k - 1, 0]) + 0.2 * _dead_zone(u[k - 2, 0])


def _offset_1e4(y, u, k):
    d = y[k - 1] - 1e4
    return 1e4 + (0.8 * d + 30 * u[k - 1, 0] if d > 0 else 0.4 * d + 60 * u[k - 1, 0] + 5)


def _irrelevant_u2(y, u, k):
    return 0.7 * y[k - 1] + u[k - 1, 0] if u[k - 1, 0] > 0.2 else 0.5 * y[k - 1] - 0.5 * u[k - 1, 0] + 0.3


def _coloured_noise(y, u, k):
    return 0.9 * y[k - 1] + 0.5 * u[k - 1, 0] if y[k - 1] < 1.0 else 0.6 * y[k - 1] + 0.2 * u[k - 1, 0] + 0.3


def _oversampled(y, u, k):
    return 0.995 * y[k - 1] + 0.005 * u[k - 1, 0] if y[k - 1] > 0 else 0.98 * y[k - 1] + 0.04 * u[k - 1, 0] - 0.002


# name: (one step, inputs (rng, n), initial outputs, true orders (na, nb, nk))
SYSTEMS = {
    "integrator_sat": (_integrator_sat, lambda r, n: _held(r, n, -1.2, 1.2, 30), [0.0], (1, 1, 1)),
    "deadzone_hammerstein": (_deadzone_hammerstein, lambda r, n: _held(r, n, -1, 1, 5), [0.0, 0.0], (2, 2, 1)),
    "offset_1e4": (_offset_1e4, lambda r, n: _held(r, n, -1, 1, 3), [1e4], (1, 1, 1)),
    "irrelevant_u2": (_irrelevant_u2, lambda r, n: _held(r, n, -1, 1, 2, 2), [0.0], (1, 1, 1)),
    "coloured_noise": (_coloured_noise, lambda r, n: _held(r, n, -1, 3, 4), [0.0], (1, 1, 1)),
    "oversampled": (_oversampled, lambda r, n: _held(r, n, -1, 1, 200), [0.0, 0.0], (1, 1, 1)),
}


def simulate(name, u, noise=None):
    step, _, y0, _ = SYSTEMS[name]
    y = np.zeros(len(u))
    y[:len(y0)] = y0
    for k in range(len(y0), len(u)):
        y[k] = step(y, u, k) + (0.0 if noise is None else noise[k])
    return y


def data(name, seed, n):
    """Training ``(u, y)`` and noise-free validation ``(u, y)`` of one seed."""
    from scipy.signal import lfilter

    inputs = SYSTEMS[name][1]
    rng = np.random.default_rng(seed)
    u = inputs(rng, n)
    e = NOISE * np.std(simulate(name, u)) * rng.standard_normal(n)
    if name == "coloured_noise":
        e = 0.3 * lfilter([1.0], [1.0, -0.9], e)
    uv = inputs(np.random.default_rng(100 + seed), N_VALID)
    return (u, simulate(name, u, e)), (uv, simulate(name, uv))


def tank_methods(seeds, n=3000) -> None:
    """``--methods``: on ``integrator_sat`` (``n`` samples, the true orders 1/1/1, 3 regions), per
    seed, the free-run fit % of ``threshold``, ``alternating``, ``hinging`` (two hinges of a
    continuous PWA map) and ``threshold-alternating`` on the noise-free validation record; the alternation's objective where ``alternating`` landed, where
    ``threshold-alternating`` landed (from the split), and at the true modes' labels; and the
    learned boundaries' input-to-output weight ratio (the true boundaries' is 0.2)."""
    from hwpts.identification import PWARX
    from hwpts.identification.segmentation.alternating import _objective, scaled_problem

    print(f"integrator_sat, {n:,} samples, na 1, nb 1, nk 1, 3 regions: free-run fit % (noise-free validation); "
          "alternation objective; boundary weight ratio |w_u / w_y|")
    print(f"{'seed':>4s} {'threshold':>10s} {'alternating':>12s} {'hinging':>8s} {'thr-alt':>8s}   {'obj alt':>8s} {'obj thr-alt':>11s} "
          f"{'obj true':>9s}   ratio")
    for seed in seeds:
        (u, y), (uv, yv) = data("integrator_sat", seed, n)
        fits, objective = {}, {}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for method in ("threshold", "alternating", "hinging", "threshold-alternating"):
                model = PWARX(1, 1, 1, n_regions=3, segmentation=method, random_state=0).fit(u, y)
                fits[method] = free_fit(model, uv, yv)
                objective[method] = model.segmentation_info_.get("objective", np.nan)
        X, t = np.column_stack([y[:-1], u[:-1, 0]]), y[1:]
        raw = X[:, 0] + 0.2 * X[:, 1]
        true = np.where(raw <= 0, 0, np.where(raw >= 10, 2, 1))
        Z, ys, Phi = scaled_problem(X, t)
        at_true = _objective(Phi, ys, Z, true, 3, 1.0, 1e-8, Z.shape[1])
        ratios = [abs(h[1] / h[0]) for H in model.partition_.H for h in H]
        print(f"{seed:4d} {fits['threshold']:10.1f} {fits['alternating']:12.1f} {fits['hinging']:8.1f} "
              f"{fits['threshold-alternating']:8.1f}   "
              f"{objective['alternating']:8.5f} {objective['threshold-alternating']:11.5f} {at_true:9.5f}   "
              f"{min(ratios):.2f}-{max(ratios):.2f}", flush=True)


def main(argv=None) -> int:
    parsed = seeds_and_systems(list(argv or []), SYSTEMS, "textbook")
    if parsed is None:
        return 2
    seeds, names = parsed
    seeds = seeds if any(a.startswith("--seeds=") for a in argv or []) else [0]
    if "--methods" in (argv or []):
        sizes = [int(a.split("=", 1)[1]) for a in argv if a.startswith("--samples=")]
        tank_methods(seeds, sizes[-1] if sizes else 3000)
        return 0
    print(f"free-run fit % on noise-free validation, median [min, max] over {len(seeds)} seed(s); "
          f"noise {NOISE:.0%} of the output's std (equation error)")
    print(f"{'system':21s} {'N':>5s} {'hwpts':>22s} {'hwpts, true orders':>22s} {'ARX':>22s} "
          f"{'search s':>8s}  chosen (na/nb/nk method regions)")
    for name in names:
        na, nb, nk = SYSTEMS[name][3]
        for n in SIZES:
            rows = {"hwpts": [], "told": [], "arx": []}
            chosen, times = [], []
            for seed in seeds:
                (u, y), (uv, yv) = data(name, seed, n)
                search, told, arx, elapsed = three_fits(u, y, {"output_order": na, "input_order": nb,
                                                                "input_delay": nk})
                times.append(elapsed)
                rows["hwpts"].append(free_fit(search.best_estimator_, uv, yv))
                rows["told"].append(free_fit(told.best_estimator_, uv, yv))
                rows["arx"].append(free_fit(arx, uv, yv))
                chosen.append(chosen_label(search.best_estimator_))
            with warnings.catch_warnings():  # a column whose every free run diverged reads nan
                warnings.simplefilter("ignore", RuntimeWarning)
                print(f"{name:21s} {n:5d} {cell(rows['hwpts']):>22s} {cell(rows['told']):>22s} "
                      f"{cell(rows['arx']):>22s} {np.median(times):8.1f}  {'; '.join(chosen)}", flush=True)
    return 0
