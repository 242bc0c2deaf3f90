"""Identification benchmark: accuracy and speed of the PWARX library, side by side with peers.

``python -m benchmarks identification [--quick] [--no-peers] [--no-real]``

hwpts and ARX fit times are the best of 3 runs; PyPARC runs once (a minute per fit).

Measured in the same run (BENCHMARKS.md):
- systems 1-3: region accuracy (median of 5 data sets, 3,000 noise-free validation samples);
- system 5 at N = 2,000 and 20,000: fit time, free-run fit and region accuracy on 3,000 noise-free
  validation samples, for hwpts, a single least-squares ARX (the floor), the oracle (least squares
  told the true modes, simulated with the true partition: the ceiling) and PyPARC (in its own
  virtual environment ``benchmarks/.venv-pyparc``, created on demand; skipped with the reason if
  that fails);
- system 5 at N = 20,000 over 10 x 10 (training, validation) pairs: the spread of the free-run fit
  of hwpts and of the oracle (one validation set is a coin flip, see bench_system5_spread), and the
  oracle alone over 50 x 20 further pairs (how often a perfect-labels estimator clears 95 %);
- free-run simulation of 10^6 samples;
- real data (when ``../shared/data`` or ``$HWPTS_DATA_DIR`` exists): pick_and_place and the
  hydraulic actuator, a fixed grid selected on the training part only (blocked cross-validation of
  the free-run fit, :class:`PWARXSearch` with ``cv=5``); the default search is ``benchmarks real``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PYPARC_VENV = HERE / ".venv-pyparc"
# numpy < 2.4: PyPARC 2.0.4 writes a one-element array into a scalar slot for K = 2 (parc.py,
# fit_PWL: gamma1[0] = -intercept_), which numpy 2.4 refuses ("setting an array element with a
# sequence"): with it the zoo's two 2-region systems had no PyPARC row
PYPARC_PACKAGES = ["numpy<2.4", "pycddlib<3", "pypoman<1.1", "scikit-learn<1.8", "pyparc"]
PYPARC_CHECK = ("import sys, numpy, pyparc.parc; "
                "sys.exit(0 if tuple(int(x) for x in numpy.__version__.split('.')[:2]) < (2, 4) else 1)")


def _pyparc_python() -> tuple[Path | None, str | None]:
    """The PyPARC interpreter, creating the venv (or bringing its packages to PYPARC_PACKAGES) on
    demand; (None, reason) if impossible."""
    py = PYPARC_VENV / "bin" / "python"
    check = [str(py), "-c", PYPARC_CHECK]
    if py.exists() and subprocess.run(check, capture_output=True).returncode == 0:
        return py, None
    print(f"{'updating' if py.exists() else 'creating'} {PYPARC_VENV.name}: installing {' '.join(PYPARC_PACKAGES)} ...",
          flush=True)
    try:
        if not py.exists():
            subprocess.run([sys.executable, "-m", "venv", str(PYPARC_VENV)], check=True, capture_output=True)
        proc = subprocess.run([str(py), "-m", "pip", "install", "--quiet", *PYPARC_PACKAGES],
                              capture_output=True, text=True, timeout=1800)
    except (subprocess.SubprocessError, OSError) as error:
        return None, f"could not create the PyPARC environment: {error}"
    if proc.returncode != 0:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        return None, "pip install failed: " + " | ".join(tail)
    probe = subprocess.run(check, capture_output=True, text=True)
    if probe.returncode != 0:
        why = probe.stderr.strip().splitlines()[-1:] or ["numpy is still >= 2.4"]
        return None, "pyparc installed but not usable: " + why[0]
    return py, None


def _run_pyparc(py, X, y, u_val, y_val, K=3, sigma=1.0):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "data.npz"
        np.savez(path, X_train=X, y_train=y, u_val=u_val, y_val=y_val)
        proc = subprocess.run([str(py), str(HERE / "peers" / "pyparc_runner.py"), str(path), str(K), str(sigma)],
                              capture_output=True, text=True, timeout=3600)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _fmt(v, spec=".2f"):
    return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, spec)


def bench_small_systems(rows):
    from hwpts.identification import PWARX, region_accuracy
    from hwpts.identification.synthetic import make_system

    for number in (1, 2, 3):
        accs = []
        for seed in range(5):
            d = make_system(number, rng=seed)
            v = make_system(number, rng=1000 + seed, sigma=0.0, n=3000)
            m = PWARX(d.na, d.nb, d.nk, n_regions=d.n_modes, segmentation="alternating", random_state=seed)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                m.fit(d.inputs, d.output)
            ok = v.modes >= 0
            accs.append(region_accuracy(v.modes[ok], m.predict_regions(v.inputs, v.output)[ok]))
        rows.append((f"system {number}", f"region accuracy median {100 * np.median(accs):.1f} % "
                     f"(min {100 * min(accs):.1f} %) over 5 data sets"))


def bench_system5(n, pyparc, lines, seed=0):
    from hwpts.identification import PWARX, region_accuracy
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.synthetic import make_system

    d = make_system(5, rng=seed, n=n)
    v = make_system(5, rng=100 + seed, n=3000, sigma=0.0)
    out = {}
    for name, params in (("hwpts alternating", dict(n_regions=3, segmentation="alternating")),
                         ("single LS ARX", dict(segmentation="average"))):
        times = []
        for _ in range(3):  # best of 3 (as timeit): the fit is deterministic, the machine is not
            t0 = time.perf_counter()
            m = PWARX(2, 2, 1, random_state=seed, **params).fit(d.inputs, d.output)
            times.append(time.perf_counter() - t0)
        ft = min(times)
        sim = m.simulate(v.inputs, v.output)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit = m.score(v.inputs, v.output)
        acc = region_accuracy(v.modes[2:], m.predict_regions(v.inputs, v.output)[2:]) if m.n_regions_ > 1 else None
        out[name] = {"fit_time_s": ft, "fit_percent": None if sim.diverged else fit, "region_accuracy": acc}
    out["oracle LS (true modes)"] = _oracle_system5(d, v)
    if pyparc[0] is not None:
        st = RegressorStructure.create(2, 2, 1, 2)
        X, y = st.build(d.inputs, d.output)
        try:
            r = _run_pyparc(pyparc[0], X, y, v.inputs, v.output)
            modes = np.asarray(r["modes"])
            ok = modes >= 0
            acc = region_accuracy(v.modes[2:][ok], modes[ok]) if ok.all() else None
            out["PyPARC (K=3, sigma=1)"] = {"fit_time_s": r["fit_time_s"], "fit_percent": r["fit_percent"],
                                           "region_accuracy": acc}
        except Exception as error:  # report and continue: the peer is optional
            lines.append(f"PyPARC at N={n} failed: {error}")
    return out


def _oracle_system5(d, v):
    """Least squares per mode with the TRUE training modes, simulated with the TRUE partition.

    No estimator can beat it at this N and noise level (it is told what every estimator must
    guess), so it bounds the free-run fit any method can be expected to reach on a validation set.
    """
    from hwpts.identification.local_models import fit_local_models
    from hwpts.identification.metrics import fit_percent
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.simulation import simulate_pwarx
    from hwpts.identification.synthetic import system5_partition

    st = RegressorStructure.create(2, 2, 1, 2)
    t0 = time.perf_counter()
    X, y = st.build(d.inputs, d.output)
    theta = fit_local_models(X, y, d.modes[st.max_lag:], 3).theta
    ft = time.perf_counter() - t0
    sim = simulate_pwarx(st, system5_partition(6), theta, v.inputs, v.output[:st.max_lag])
    fit = None if sim.diverged else fit_percent(v.output[st.max_lag:], sim.output[st.max_lag:])
    return {"fit_time_s": ft, "fit_percent": fit, "region_accuracy": 1.0}


def bench_system5_spread(n=20000, n_train=10, n_val=10):
    """Free-run fit of hwpts and of the oracle over n_train x n_val (training, validation) pairs.

    The free run of system 5 is sensitive to tiny parameter errors (a sample that lands on the
    other side of a boundary switches the mode and the error propagates), so one validation set
    says little; the spread over pairs is what an estimator controls.
    """
    from hwpts.identification import PWARX
    from hwpts.identification.synthetic import make_system

    vals = [make_system(5, rng=100 + j, n=3000, sigma=0.0) for j in range(n_val)]
    res = {"hwpts alternating": [], "oracle LS (true modes)": []}
    for seed in range(n_train):
        d = make_system(5, rng=seed, n=n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m = PWARX(2, 2, 1, n_regions=3, segmentation="alternating", random_state=seed).fit(d.inputs, d.output)
            for v in vals:
                res["hwpts alternating"].append(m.score(v.inputs, v.output))
                res["oracle LS (true modes)"].append(_oracle_system5(d, v)["fit_percent"])
    return {k: np.asarray(a, dtype=float) for k, a in res.items()}


def bench_oracle_chance(n=20000, n_train=50, n_val=20):
    """The oracle alone over n_train x n_val pairs (its own seeds): how often ANY estimator that is
    as good as least squares told the true modes clears 95 % on one validation set."""
    from hwpts.identification.synthetic import make_system

    vals = [make_system(5, rng=1000 + j, n=3000, sigma=0.0) for j in range(n_val)]
    fits = []
    for seed in range(2000, 2000 + n_train):
        d = make_system(5, rng=seed, n=n)
        fits += [_oracle_system5(d, v)["fit_percent"] for v in vals]
    return np.asarray(fits, dtype=float)


def bench_simulation(lines):
    from hwpts.identification import PWARX
    from hwpts.identification.synthetic import make_system

    d = make_system(5, rng=0, n=5000)
    m = PWARX(2, 2, 1, n_regions=3, segmentation="alternating", random_state=0).fit(d.inputs, d.output)
    u = np.random.default_rng(1).uniform(-1, 1, (1_000_000, 2))
    m.simulate(u[:100], np.zeros(100))
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        sim = m.simulate(u, np.zeros(1_000_000))
        times.append(time.perf_counter() - t0)
    assert not sim.diverged
    return min(times)


def bench_real(lines):
    """Fixed grids on pick_and_place and the hydraulic actuator, chosen by :class:`PWARXSearch`
    (5 contiguous blocks of the training record, each simulated in free run by the candidate fitted
    on the other four; the best mean wins outright, as ``GridSearchCV``). The default search
    (orders, method and regions chosen) is ``python -m benchmarks real``."""
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.selection import expand_grid
    from hwpts.io.datasets import read_table

    root = Path(os.environ.get("HWPTS_DATA_DIR", HERE.parent.parent / "shared" / "data"))
    base = PWARX(input_delay=1, random_state=0)
    pp = root / "pick_and_place" / "pick_and_place_400Hz.csv"
    if pp.exists():
        c = read_table(pp)
        u, y = c["u"][:, None], c["y"]
        utr, ytr, ute, yte = u[:5000], y[:5000], u[-1001:], y[-1001:]
        arx = PWARX(2, 2, 1, segmentation="average").fit(utr, ytr).score(ute, yte)
        grid = []
        for na in (1, 2, 3, 4):
            for nb in (1, 2, 3, 4):
                grid += expand_grid({"output_order": [na], "input_order": [nb], "segmentation": ["alternating"],
                                     "n_regions": [2, 3], "partition_columns": [None, ["y(k-1)"]],
                                     "polish": [False, True]})
                grid += expand_grid({"output_order": [na], "input_order": [nb], "segmentation": ["threshold"],
                                     "n_regions": [2, 3], "polish": [False, True]})
        t0 = time.perf_counter()
        search = PWARXSearch(base, grid, cv=5, try_polish=False, tolerance=0.0, n_standard_errors=0.0).fit(utr, ytr)
        elapsed = time.perf_counter() - t0
        lines.append(f"pick_and_place: test free-run fit {search.score(ute, yte):.2f} % (plain ARX {arx:.2f} %), "
                     f"chosen on training only {search.best_params_} from {len(search.cv_results_)} candidates "
                     f"in {elapsed:.0f} s")
    else:
        lines.append(f"pick_and_place: skipped, {pp} not found")
    act = root / "hydraulic_actuator" / "actuator.csv"
    if act.exists():
        c = read_table(act)
        u, y = c["u_valve_opening"][:, None], c["y_oil_pressure"]
        utr, ytr, ute, yte = u[:512], y[:512], u[512:], y[512:]
        arx = PWARX(3, 2, 1, segmentation="average").fit(utr, ytr).score(ute, yte)
        grid = []
        for na, nb in [(3, 2), (3, 3)]:
            grid += expand_grid({"output_order": [na], "input_order": [nb],
                                 "segmentation": ["average", "kmeans", "clustering", "alternating"],
                                 "n_regions": [2, 3], "polish": [False, True]})
        search = PWARXSearch(base, grid, cv=5, try_polish=False).fit(utr, ytr)
        diverged = sum(bool(r["diverged"]) for r in search.cv_results_)
        lines.append(f"hydraulic_actuator: test free-run fit {search.score(ute, yte):.2f} % (plain ARX {arx:.2f} %), "
                     f"chosen {search.best_params_}; {diverged} of {len(search.cv_results_)} candidates diverged")
    else:
        lines.append(f"hydraulic_actuator: skipped, {act} not found")


def main(argv=None) -> int:
    argv = list(argv or [])
    quick = "--quick" in argv
    peers = "--no-peers" not in argv
    lines: list[str] = []
    pyparc = (None, "disabled by --no-peers")
    if peers:
        pyparc = _pyparc_python()
        if pyparc[0] is None:
            print(f"PyPARC unavailable: {pyparc[1]}; continuing without it", flush=True)
    # warm-up: imports, numba cache, scikit-learn code paths (not part of any timing)
    from hwpts.identification import PWARX
    from hwpts.identification.synthetic import make_system

    d = make_system(5, rng=9, n=500)
    PWARX(2, 2, 1, n_regions=3, segmentation="alternating", random_state=0).fit(d.inputs, d.output).simulate(
        d.inputs, d.output)
    small: list = []
    bench_small_systems(small)
    print("\nSynthetic systems 1-3 (BENCHMARKS.md), method alternating:")
    for name, text in small:
        print(f"  {name}: {text}")
    sizes = (2000,) if quick else (2000, 20000)
    for n in sizes:
        res = bench_system5(n, pyparc, lines)
        base = res["hwpts alternating"]["fit_time_s"]
        print(f"\nSystem 5, N = {n:,} (validation: 3,000 noise-free samples)")
        print(f"  {'method':24s} {'fit time [s]':>12s} {'time / hwpts':>12s} {'free-run fit %':>15s} {'region acc %':>13s}")
        for name, r in res.items():
            acc = None if r["region_accuracy"] is None else 100 * r["region_accuracy"]
            print(f"  {name:24s} {r['fit_time_s']:12.3f} {r['fit_time_s'] / base:12.1f} "
                  f"{_fmt(r['fit_percent']):>15s} {_fmt(acc):>13s}")
    if not quick:
        spread = bench_system5_spread()
        print("\nSystem 5, N = 20,000: free-run fit over 10 training x 10 validation sets (100 pairs)")
        print(f"  {'method':24s} {'median':>7s} {'10th pct':>8s} {'min':>6s} {'share >= 95 %':>13s}")
        for name, a in spread.items():
            a = a[np.isfinite(a)]
            print(f"  {name:24s} {np.median(a):7.2f} {np.percentile(a, 10):8.2f} {a.min():6.2f} "
                  f"{100 * np.mean(a >= 95):12.0f} %")
        diff = spread["hwpts alternating"] - spread["oracle LS (true modes)"]
        print(f"  hwpts minus oracle, pair by pair: mean {np.nanmean(diff):+.2f}, median {np.nanmedian(diff):+.2f} points")
        chance = bench_oracle_chance()
        print(f"  {'oracle, 1,000 more pairs':24s} {np.median(chance):7.2f} {np.percentile(chance, 10):8.2f} "
              f"{chance.min():6.2f} {100 * np.mean(chance >= 95):12.1f} %")
    t_sim = bench_simulation(lines)
    print(f"\nFree-run simulation of 10^6 samples (3 regions, na=nb=2, 2 inputs): {t_sim:.3f} s "
          f"({'within' if t_sim < 1 else 'ABOVE'} the 1 s target)")
    if not quick and "--no-real" not in argv:
        print("\nReal data (selection on the training part only):", flush=True)
        bench_real(lines)
    for line in lines:
        print(f"  {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
