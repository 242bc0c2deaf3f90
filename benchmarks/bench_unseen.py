"""Systems the default search was never tuned on: five PWARX systems written for this check, none
of them in the zoo, the real data or the tests (and a sixth, ``dead_time_5``, added later with the
capability it checks).

| system | what makes it hard |
|---|---|
| ``mimo_switch_u2`` | two inputs; the mode switches on the sign of the second input ``u2(k-1)`` |
| ``third_order_switch_y2`` | third order (na 3, nb 2); switches on the sign of ``y(k-2)`` |
| ``oblique_3`` | three modes behind two oblique boundaries; one mode holds about 1 % of the rows |
| ``slow_pole_sat`` | a slow pole (0.95) and a saturated input: three modes, steps held 20 samples |
| ``oe_two_mode`` | two modes switching on ``y(k-1)``, with *output-error* noise (not equation error) |
| ``dead_time_5`` | two modes switching on ``y(k-1)``, the input acting after a dead time of 5 samples (added with the delay estimate it checks: the orders grid's delays are 0 and 1) |

Each seed: 2,000 training samples with noise of 5 % of the noise-free output's standard deviation
(equation error, except ``oe_two_mode``), 3,000 noise-free validation samples from another input
realisation. Rows, as free-run fit % on the validation data (from its first measured outputs):

- ``hwpts``: the default search, orders chosen (``PWARXSearch(PWARX(random_state=0), orders="auto")``);
- ``hwpts, true orders``: the same search told the system's orders;
- ``oracle``: least squares told every training sample's true mode, simulated with the true
  partition (on ``oe_two_mode`` equation-error least squares is biased: no ceiling there);
- ``ARX``: one affine ARX model with the true orders (the floor).

``python -m benchmarks unseen [--seeds=N] [--systems=a,b]``: medians and ranges over the seeds,
the orders and models chosen, and the search time.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

NOISE = 0.05  # noise standard deviation, as a share of the noise-free output's
N_TRAIN, N_VALID = 2000, 3000


def _system(na, nb, nk, n_inputs, thetas, region, inputs, output_error=False):
    return {"na": na, "nb": nb, "nk": nk, "n_inputs": n_inputs, "theta": [np.asarray(t, float) for t in thetas],
            "region": region, "inputs": inputs, "output_error": output_error}


def _held(rng, n, low, high, hold):
    """A random staircase: levels uniform in [low, high] held ``hold`` samples."""
    return np.repeat(rng.uniform(low, high, (n // hold + 1, 1)), hold, axis=0)[:n]


# regressor phi = [y(k-1) .. y(k-na), u1(k-nk) .. u1(k-nk-nb+1), u2 ..., 1]; theta per mode over it
SYSTEMS = {
    "mimo_switch_u2": _system(1, 1, 1, 2, [[0.6, 0.5, 0.8, 0.0], [0.6, 0.5, -0.2, 0.0]],
                              lambda p: 0 if p[2] > 0 else 1, lambda r, n: r.uniform(-1, 1, (n, 2))),
    "third_order_switch_y2": _system(3, 2, 1, 1, [[1.5, -0.9, 0.2, 1.0, 0.5, 0.1], [1.1, -0.5, 0.1, 0.4, 0.2, -0.1]],
                                     lambda p: 0 if p[1] > 0 else 1, lambda r, n: r.normal(0, 1, (n, 1))),
    "oblique_3": _system(1, 1, 1, 1, [[0.5, 1.0, 0.0], [0.8, -0.5, 0.3], [0.2, 0.7, -0.4]],
                         lambda p: 0 if p[0] + p[1] < -0.5 else (1 if p[0] - p[1] < 0.5 else 2),
                         lambda r, n: r.uniform(-2, 2, (n, 1))),
    "slow_pole_sat": _system(1, 2, 1, 1, [[0.95, 0.1, 0.05, 0.0], [0.95, 0.0, 0.0, 0.15], [0.95, 0.0, 0.0, -0.15]],
                             lambda p: 0 if abs(p[1]) <= 1 else (1 if p[1] > 1 else 2),
                             lambda r, n: _held(r, n, -2.5, 2.5, 20)),
    "oe_two_mode": _system(2, 1, 1, 1, [[1.2, -0.5, 1.0, 0.0], [0.9, -0.3, 0.3, 0.2]],
                           lambda p: 0 if p[0] > 0 else 1, lambda r, n: r.uniform(-1, 1, (n, 1)),
                           output_error=True),
    # added with the delay estimate it checks (not unseen by it): a dead time of 5 samples
    "dead_time_5": _system(2, 2, 5, 1, [[1.2, -0.5, 0.6, 0.3, 0.0], [0.9, -0.3, 0.25, 0.1, 0.1]],
                           lambda p: 0 if p[0] > 0 else 1, lambda r, n: _held(r, n, -1, 1, 3)),
}


def _phi(S, y, u, k):
    v = [y[k - i] for i in range(1, S["na"] + 1)]
    for j in range(u.shape[1]):
        v += [u[k - S["nk"] - i, j] for i in range(S["nb"])]
    return np.array(v + [1.0])


def _max_lag(S):
    return max(S["na"], S["nk"] + S["nb"] - 1)


def simulate(S, u, noise=None, theta=None, y0=None):
    """Output and true modes of system ``S`` driven by ``u`` (equation-error ``noise`` if given),
    from zero or from the first outputs ``y0``."""
    theta = S["theta"] if theta is None else theta
    n, m = u.shape[0], _max_lag(S)
    y, modes = np.zeros(n), np.full(n, -1)
    if y0 is not None:
        y[:m] = y0[:m]
    for k in range(m, n):
        p = _phi(S, y, u, k)
        modes[k] = S["region"](p)
        y[k] = p @ theta[modes[k]] + (0.0 if noise is None else noise[k])
    return y, modes


def data(S, seed):
    """Training ``(u, y, modes)`` and noise-free validation ``(u, y)`` of one seed."""
    rng = np.random.default_rng(seed)
    u = S["inputs"](rng, N_TRAIN)
    clean, modes = simulate(S, u)
    sigma = NOISE * np.std(clean)
    if S["output_error"]:
        y = clean + sigma * rng.standard_normal(N_TRAIN)
    else:
        y, modes = simulate(S, u, noise=sigma * rng.standard_normal(N_TRAIN))
    uv = S["inputs"](np.random.default_rng(10_000 + seed), N_VALID)
    yv, _ = simulate(S, uv)
    return (u, y, modes), (uv, yv)


def oracle_fit(S, train, valid):
    """Free-run fit of least squares told the training modes, simulated with the true partition."""
    from hwpts.identification import fit_percent

    u, y, modes = train
    m = _max_lag(S)
    X = np.array([_phi(S, y, u, k) for k in range(m, len(y))])
    t, md = y[m:], modes[m:]
    theta = [np.linalg.lstsq(X[md == i], t[md == i], rcond=None)[0] for i in range(len(S["theta"]))]
    uv, yv = valid
    ys, _ = simulate(S, uv, theta=theta, y0=yv)
    return fit_percent(yv[m:], ys[m:])


def free_fit(model, uv, yv):
    """Free-run fit % from the validation's first outputs (``nan`` if the run diverged)."""
    return model.simulate(uv, yv).score(yv)


def three_fits(u, y, true):
    """The default search (orders chosen), the search told the orders ``true`` (a dict of
    ``output_order``, ``input_order``, ``input_delay``), one ARX model of those orders, and the
    default search's time in seconds."""
    from hwpts.identification import PWARX, PWARXSearch

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, y)
        elapsed = time.perf_counter() - t0
        told = PWARXSearch(PWARX(random_state=0, **true)).fit(u, y)
        arx = PWARX(**true, n_regions=1, segmentation="average").fit(u, y)
    return search, told, arx, elapsed


def run(name, seeds):
    S = SYSTEMS[name]
    true = {"output_order": S["na"], "input_order": S["nb"], "input_delay": S["nk"]}
    rows = {"hwpts": [], "hwpts, true orders": [], "oracle": [], "ARX": []}
    chosen, times = [], []
    for seed in seeds:
        train, valid = data(S, seed)
        u, y, _ = train
        search, told, arx, elapsed = three_fits(u, y, true)
        times.append(elapsed)
        rows["hwpts"].append(free_fit(search.best_estimator_, *valid))
        rows["hwpts, true orders"].append(free_fit(told.best_estimator_, *valid))
        rows["oracle"].append(oracle_fit(S, train, valid))
        rows["ARX"].append(free_fit(arx, *valid))
        chosen.append(chosen_label(search.best_estimator_))
    return rows, chosen, times


def chosen_label(model) -> str:
    """``na/nb/nk method regions [powers p,q] [polished]`` of a fitted model."""
    st = model.structure_
    return (f"{st.na}/{st.nb[0]}/{st.nk[0]} {model.segmentation_info_.get('method')} {model.n_regions_}"
            f"{' powers ' + ','.join(map(str, st.output_powers)) if st.output_powers else ''}"
            f"{' polished' if model.summary()['polished'] else ''}")


def seeds_and_systems(argv, systems, label):
    """``(seeds, names)`` from ``--seeds=N`` (3) and ``--systems=a,b`` (all of ``systems``), or
    ``None`` after naming an unknown system on stderr."""
    n_seeds, names = 3, list(systems)
    for a in argv:
        if a.startswith("--seeds="):
            n_seeds = max(1, int(a.split("=", 1)[1]))
        elif a.startswith("--systems="):
            names = a.split("=", 1)[1].split(",")
    unknown = [n for n in names if n not in systems]
    if unknown:
        print(f"{label}: unknown system(s) {unknown}; available: {list(systems)}", file=sys.stderr)
        return None
    return list(range(n_seeds)), names


def cell(values, min_width: int = 5) -> str:
    """``median [min, max]`` of fits over the seeds (``nan`` left out)."""
    v = np.asarray(values, float)
    return f"{np.nanmedian(v):6.1f} [{np.nanmin(v):{min_width}.1f}, {np.nanmax(v):5.1f}]"


def main(argv=None) -> int:
    parsed = seeds_and_systems(list(argv or []), SYSTEMS, "unseen")
    if parsed is None:
        return 2
    seeds, names = parsed
    n_seeds = len(seeds)
    print(f"free-run fit % on noise-free validation, median [min, max] over {n_seeds} seed(s); "
          f"{N_TRAIN} training samples, noise {NOISE:.0%} of the output's std")
    print(f"{'system':24s} {'hwpts':>22s} {'hwpts, true orders':>22s} {'oracle':>22s} {'ARX':>8s} "
          f"{'search s':>8s}  chosen (na/nb/nk method regions)")
    for name in names:
        rows, chosen, times = run(name, seeds)
        oracle = cell(rows["oracle"]) + ("*" if SYSTEMS[name]["output_error"] else " ")
        print(f"{name:24s} {cell(rows['hwpts']):>22s} {cell(rows['hwpts, true orders']):>22s} {oracle:>22s} "
              f"{np.nanmedian(rows['ARX']):8.1f} {np.median(times):8.1f}  {'; '.join(chosen)}", flush=True)
    print("* output-error noise: equation-error least squares told the modes is biased, not a ceiling")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
