"""The literature's PWARX systems (``../shared/benchmarks/pwarx_zoo.py``), side by side in one run.

For every system of the zoo and every seed: training data drawn with the source's N and noise,
validation on noise-free data of another seed (3,000 samples for dynamic systems, 2,000 for static
maps). Rows:

- ``oracle``: least squares told every training sample's true mode, validated with the true
  partition (the ceiling of any estimator at that N and noise);
- ``modes``: least squares told every training sample's true mode, with the partition learned
  from those modes by hwpts's region classifier (the ceiling of any estimator that must find the
  boundaries from the training samples: on a discontinuous map, a boundary known only to lie
  between two training samples costs fit that no estimator can recover);
- ``arx``: one affine ARX model (the floor);
- ``hwpts``: the library's default (:class:`hwpts.identification.PWARXSearch` on a ``PWARX`` with
  the system's orders; the number of regions and the method chosen on the training data only);
- ``pyparc``: PyPARC 2.0 told the true number of regions (its own venv, as the identification
  benchmark; skipped with the reason when it cannot be installed, or with ``--no-peers``); its
  k-means start seeded with the data set's seed, so two runs give the same column.

One-step fit % (NRMSE) on the validation data is the headline; free-run fit (dynamic systems with
an autoregressive part) is reported with its spread; region accuracy where modes exist (best
matching of estimated to true regions). Systems without true parameters (function
approximations) have no oracle row: PyPARC is their reference.

``--told-regions``: one more line per system, ``hwpts, K told``: the same search told the true
number of regions, as PyPARC is (``PWARXSearch(..., n_regions=K)``, ``hwpts identify --regions K``:
the method still chosen), its one-step fit, region accuracy, time and free run.

``--variants``: instead of the zoo's systems, its ``pwarx_random`` generator with other settings
(:data:`VARIANTS`: other instances, orders, numbers of modes, partitions, noise, and modes sharing
parameters), the systems the default was not tuned on.

``--sizes=20000,100000,1000000``: instead, ``pwarx_random`` itself (the zoo's instance: 6 modes,
na 2, nb 2) with these numbers of training samples, the zoo's "N from 1e4 to 1e6" (with
``--seeds=1 --no-peers`` at a million samples: the search takes minutes there, PyPARC far longer).

``python -m benchmarks zoo [--seeds=N] [--systems=a,b] [--variants | --sizes=N,N] [--told-regions] [--no-peers]`` (with
``--variants``, ``--systems`` names variants)
"""

from __future__ import annotations

import importlib.util
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
ZOO_PATH = Path(os.environ.get("HWPTS_ZOO", HERE.parent.parent / "shared" / "benchmarks" / "pwarx_zoo.py"))
TARGET_GAP = 2.0  # points below the oracle's median one-step fit

# --variants: pwarx_random's generator with settings other than the zoo's (label -> keyword arguments)
VARIANTS = {
    "rand_3m_n2000": {"n": 2000, "n_modes": 3},
    "rand_4slabs": {"n": 5000, "n_modes": 4, "partition": "slabs"},
    "rand_na3nb1_i3": {"n": 5000, "n_modes": 4, "na": 3, "nb": 1, "instance_seed": 3},
    "rand_na1nb3_i5": {"n": 3000, "n_modes": 3, "na": 1, "nb": 3, "instance_seed": 5},
    "rand_2m_noisy": {"n": 1000, "n_modes": 2, "sigma": 0.2, "instance_seed": 11},
    "rand_6m_shared3": {"n": 20000, "n_modes": 6, "n_distinct": 3},
    "rand_vor5_d2": {"n": 5000, "n_modes": 5, "n_distinct": 2, "instance_seed": 7},
    "rand_vor4_na1": {"n": 4000, "n_modes": 4, "n_distinct": 2, "na": 1, "nb": 2, "instance_seed": 13},
    "rand_ababa": {"n": 6000, "n_modes": 5, "partition": "slabs", "n_distinct": 2, "instance_seed": 9},
    "rand_abcabc": {"n": 10000, "n_modes": 6, "partition": "slabs", "n_distinct": 3, "instance_seed": 5},
    "rand_abab": {"n": 5000, "n_modes": 4, "partition": "slabs", "n_distinct": 2},
    "rand_abab_i2": {"n": 5000, "n_modes": 4, "partition": "slabs", "n_distinct": 2, "instance_seed": 2},
    "rand_aba_i4": {"n": 3000, "n_modes": 3, "partition": "slabs", "n_distinct": 2, "instance_seed": 4},
}


def load_zoo():
    """The zoo module, or None when ``../shared/benchmarks/pwarx_zoo.py`` is absent."""
    if not ZOO_PATH.exists():
        return None
    spec = importlib.util.spec_from_file_location("pwarx_zoo", ZOO_PATH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["pwarx_zoo"] = module
    spec.loader.exec_module(module)
    return module


def orders(d):
    """(na, nb, nk, inputs) of a zoo data set in hwpts's terms (static maps: nb = 1, nk = 0 per feature)."""
    if d.kind in ("pwa_static", "function"):
        X = np.asarray(d.inputs, float).reshape(len(d.output), -1)
        return 0, 1, 0, X
    u = np.asarray(d.inputs, float).reshape(len(d.output), -1)
    return d.na, d.nb, d.nk, u


def validation_n(d):
    return 3000 if d.kind == "pwarx" else 2000


def hwpts_default(na, nb, nk, u, y, seed, n_regions="auto"):
    """What a user gets without choosing anything but the orders (and, told, the number of regions)."""
    from hwpts.identification import PWARX

    try:
        from hwpts.identification import PWARXSearch
    except ImportError:  # before the model search existed: the CLI's default
        return PWARX(na, nb, nk, segmentation="auto", random_state=seed).fit(u, y)
    search = PWARXSearch(PWARX(output_order=na, input_order=nb, input_delay=nk, random_state=seed), n_regions=n_regions)
    return search.fit(u, y).best_estimator_


def oracle_theta(zoo, d):
    Phi, Y, M = d.regressors()
    ok = M >= 0
    A = np.column_stack([Phi[ok], np.ones(ok.sum())])
    theta = np.zeros((d.n_modes, A.shape[1]))
    for i in range(d.n_modes):
        sel = M[ok] == i
        if sel.sum() > 0:
            theta[i] = np.linalg.lstsq(A[sel], Y[ok][sel], rcond=None)[0]
    return theta


def learned_partition(Phi, modes, s):
    """The library's region classifier of the labelled rows ``Phi`` (modes ``0 .. s-1``), as a
    learned partition ends: the logistic classifier, sharpened when it misclassifies some of its
    rows although they are separable (``PartitionLearner.sharpen``)."""
    from hwpts.identification.partition import PartitionLearner, fit_linear_partition

    part = fit_linear_partition(Phi, modes, s)
    return PartitionLearner().sharpen(Phi, modes, part, s)


def one_step_fit(y, yhat):
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean()))


def run_system(zoo, name, seeds, pyparc_py, progress=None, kw=None, told=False):
    """Rows of every estimator on ``name``'s data sets; ``kw``: the generator's settings (default:
    the zoo's, N = 20,000 for ``pwarx_random``); ``told``: also the search told the number of regions."""
    from hwpts.identification import region_accuracy

    gen, meta = zoo.SYSTEMS[name]
    if kw is None:
        kw = {"n": 20000} if name == "pwarx_random" else {}
    same = {k: v for k, v in kw.items() if k not in ("n", "sigma")}  # the instance, validated noise-free
    rows = {k: {"onestep": [], "freerun": [], "regions": [], "time": [], "n_regions": []}
            for k in ("oracle", "modes", "arx", "hwpts", "told", "pyparc")}
    notes = []
    for seed in seeds:
        d = gen(rng=seed, **kw)
        v = gen(n=validation_n(d), sigma=0.0, rng=10_000 + seed, **same)
        if name == "hit_approx_sin":  # a fixed grid: validate on a 4x finer grid of the same interval
            v = gen(n=4 * 60, sigma=0.0)
        na, nb, nk, u = orders(d)
        _, _, _, uv = orders(v)
        Phi_v, Y_v, M_v = v.regressors()
        ok_v = M_v >= 0 if v.modes is not None and np.any(v.modes >= 0) else np.ones(len(Y_v), bool)
        dynamic = d.kind == "pwarx" and na > 0
        # oracle
        if d.theta is not None:
            th = oracle_theta(zoo, d)
            reg = d.region_fn(Phi_v)
            yhat = np.einsum("ij,ij->i", np.column_stack([Phi_v, np.ones(len(Phi_v))]), th[reg])
            rows["oracle"]["onestep"].append(one_step_fit(Y_v[ok_v], yhat[ok_v]))
            if dynamic:
                m = max(na, nb + nk - 1)
                ys, _ = zoo.simulate_pwarx(th, d.region_fn, uv, na, nb, nk, v.output[:m])
                rows["oracle"]["freerun"].append(one_step_fit(v.output[m:], ys[m:]) if np.all(np.isfinite(ys)) else np.nan)
        # modes: the true training modes, the partition learned from them
        from hwpts.identification import PWARX

        if d.theta is not None:
            Phi, Y, M = d.regressors()
            okm = M >= 0
            part = learned_partition(Phi[okm], M[okm], d.n_modes)
            reg = part.predict(Phi_v)
            yhat = np.einsum("ij,ij->i", np.column_stack([Phi_v, np.ones(len(Phi_v))]), th[reg])
            rows["modes"]["onestep"].append(one_step_fit(Y_v[ok_v], yhat[ok_v]))

        for key in ("arx", "hwpts", *(("told",) if told else ())):
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    if key == "arx":
                        model = PWARX(na, nb, nk, n_regions=1, segmentation="average").fit(u, d.output)
                    else:
                        model = hwpts_default(na, nb, nk, u, d.output, seed,
                                              d.n_modes if key == "told" else "auto")
                except Exception as error:  # noqa: BLE001 - a benchmark reports, it does not stop
                    notes.append(f"{key} seed {seed}: {type(error).__name__}: {error}")
                    continue
                elapsed = time.perf_counter() - t0
                yhat = model.predict(uv, v.output)
                m = model.structure_.max_lag
                mm = len(v.output) - len(Y_v)  # zoo rows start after the zoo's own max lag
                start = max(m, mm)
                onestep = one_step_fit(v.output[start:][ok_v[start - mm:]], yhat[start:][ok_v[start - mm:]])
                rows[key]["onestep"].append(onestep)
                rows[key]["time"].append(elapsed)
                rows[key]["n_regions"].append(int(model.n_regions_))
                if key == "hwpts" and model.structure_.output_powers:
                    notes.append(f"hwpts seed {seed}: output powers {list(model.structure_.output_powers)} chosen")
                if dynamic:
                    sim = model.simulate(uv, v.output)
                    rows[key]["freerun"].append(np.nan if sim.diverged else one_step_fit(v.output[m:], sim.output[m:]))
                if d.theta is not None and key in ("hwpts", "told"):
                    regions = model.predict_regions(uv, v.output)[mm:]
                    rows[key]["regions"].append(100 * region_accuracy(M_v[ok_v], regions[ok_v]))
        # pyparc
        if pyparc_py is not None:
            Phi, Y, M = d.regressors()
            try:
                out = _run_pyparc(pyparc_py, Phi, Y, Phi_v, d.n_modes, seed)
            except RuntimeError as error:
                notes.append(f"pyparc seed {seed}: {error}")
            else:
                rows["pyparc"]["onestep"].append(one_step_fit(Y_v[ok_v], out["yhat"][ok_v]))
                rows["pyparc"]["time"].append(out["fit_time_s"])
                rows["pyparc"]["n_regions"].append(d.n_modes)
                if d.theta is not None:
                    rows["pyparc"]["regions"].append(100 * region_accuracy(M_v[ok_v], out["regions"][ok_v]))
        if progress is not None:
            progress.update(1)
    return rows, notes


def _run_pyparc(py, X, y, Xv, K, seed):
    with tempfile.TemporaryDirectory() as tmp:
        path, out = Path(tmp) / "data.npz", Path(tmp) / "out.npz"
        np.savez(path, X_train=X, y_train=y, X_val=Xv)
        proc = subprocess.run([str(py), str(HERE / "peers" / "pyparc_zoo_runner.py"), str(path), str(K), str(out),
                               str(seed)],
                              capture_output=True, text=True, timeout=3600)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "failed")
        info = json.loads(proc.stdout.strip().splitlines()[-1])
        res = np.load(out)
        return {"yhat": res["yhat"], "regions": res["regions"], **info}


def _med(values, spec=".1f"):
    vals = [v for v in values if v is not None and np.isfinite(v)]
    if not vals:
        return "-"
    return format(float(np.median(vals)), spec)


def _spread(values):
    vals = np.array([v for v in values if v is not None], float)
    if vals.size == 0:
        return "-"
    fin = vals[np.isfinite(vals)]
    div = int(np.sum(~np.isfinite(vals)))
    if fin.size == 0:
        return f"diverged x{div}"
    text = f"{np.median(fin):.1f} [{np.percentile(fin, 10):.1f}, {np.max(fin):.1f}]"
    return text + (f" div x{div}" if div else "")


def main(argv=None) -> int:
    argv = list(argv or [])
    zoo = load_zoo()
    if zoo is None:
        print(f"zoo benchmark skipped: {ZOO_PATH} not found (set HWPTS_ZOO)")
        return 0
    n_seeds = 10
    variants = "--variants" in argv
    sizes = []
    known = list(VARIANTS) if variants else list(zoo.SYSTEMS)
    systems = known
    for a in argv:
        if a.startswith("--seeds="):
            n_seeds = int(a.split("=", 1)[1])
        elif a.startswith("--sizes="):
            try:
                sizes = [int(v) for v in a.split("=", 1)[1].split(",")]
            except ValueError:
                sizes = []
            if not sizes or min(sizes) < 100:
                print(f"zoo: --sizes: expected numbers of samples >= 100 separated by commas; got {a.split('=', 1)[1]!r}",
                      file=sys.stderr)
                return 2
        elif a.startswith("--systems="):  # with --variants: variant labels
            systems = [s for s in a.split("=", 1)[1].split(",") if s]
            unknown = [s for s in systems if s not in known]
            if unknown or not systems:
                print(f"zoo: --systems: expected names among {', '.join(known)}; got {', '.join(unknown) or 'none'}",
                      file=sys.stderr)
                return 2
    if sizes:  # (label, system, generator settings)
        runs = [(f"N={n:,}", "pwarx_random", {"n": n}) for n in sizes]
    elif variants:
        runs = [(label, "pwarx_random", VARIANTS[label]) for label in systems]
    else:
        runs = [(name, name, None) for name in systems]
    pyparc_py = None
    if "--no-peers" not in argv:
        from benchmarks.bench_identification import _pyparc_python

        pyparc_py, reason = _pyparc_python()
        if pyparc_py is None:
            print(f"PyPARC unavailable: {reason}; continuing without it", flush=True)
    seeds = list(range(n_seeds))
    print(f"zoo: {len(runs)} systems x {n_seeds} seeds; one-step fit % on noise-free validation data "
          f"(median over seeds); free run: median [10th percentile, max]", flush=True)
    header = (f"{'system':15s} {'oracle':>7s} {'modes':>6s} {'arx':>6s} {'hwpts':>6s} {'pyparc':>6s} {'gap':>6s} "
              f"{'regions':>7s} {'acc %':>6s} {'pp acc':>6s} {'hwpts s':>7s} {'pp s':>6s}  free run (hwpts | oracle)")
    print(header)
    print("-" * len(header))
    failures = []
    summary = {}
    for name, system, kw in runs:
        rows, notes = run_system(zoo, system, seeds, pyparc_py, kw=kw, told="--told-regions" in argv)
        ref = zoo.REFERENCE.get(system, {}) if kw is None else {"generator": system, **kw}
        oracle = _med(rows["oracle"]["onestep"])
        hw = _med(rows["hwpts"]["onestep"])
        pp = _med(rows["pyparc"]["onestep"])
        gap = "-"
        if rows["oracle"]["onestep"] and rows["hwpts"]["onestep"]:
            g = float(np.median(rows["hwpts"]["onestep"]) - np.median(rows["oracle"]["onestep"]))
            gap = f"{g:+.1f}"
            if g < -TARGET_GAP:
                failures.append(f"{name}: {g:+.1f} points from the oracle")
        if rows["pyparc"]["onestep"] and rows["hwpts"]["onestep"]:
            if np.median(rows["hwpts"]["onestep"]) < np.median(rows["pyparc"]["onestep"]):
                failures.append(f"{name}: below PyPARC")
        nreg = _med(rows["hwpts"]["n_regions"], ".0f")
        fr = ""
        if rows["hwpts"]["freerun"]:
            fr = f"{_spread(rows['hwpts']['freerun'])} | {_spread(rows['oracle']['freerun'])}"
        print(f"{name:15s} {oracle:>7s} {_med(rows['modes']['onestep']):>6s} {_med(rows['arx']['onestep']):>6s} {hw:>6s} {pp:>6s} {gap:>6s} "
              f"{nreg:>7s} {_med(rows['hwpts']['regions']):>6s} {_med(rows['pyparc']['regions']):>6s} "
              f"{_med(rows['hwpts']['time'], '.2f'):>7s} {_med(rows['pyparc']['time'], '.2f'):>6s}  {fr}", flush=True)
        if rows["told"]["onestep"]:
            fr = _spread(rows["told"]["freerun"]) if rows["told"]["freerun"] else ""
            print(f"{'  K told':15s} {'':>7s} {'':>6s} {'':>6s} {_med(rows['told']['onestep']):>6s} {'':>6s} {'':>6s} "
                  f"{_med(rows['told']['n_regions'], '.0f'):>7s} {_med(rows['told']['regions']):>6s} {'':>6s} "
                  f"{_med(rows['told']['time'], '.2f'):>7s} {'':>6s}  {fr}", flush=True)
        for note in notes[:3]:
            print(f"    note: {note}")
        if len(notes) > 3:
            print(f"    ({len(notes) - 3} more notes)")
        summary[name] = {k: {kk: [float(x) for x in vv] for kk, vv in v.items()} for k, v in rows.items()}
        summary[name]["reference"] = ref
    print(f"target: hwpts within {TARGET_GAP} points of the oracle's median one-step fit and at least PyPARC's "
          f"on every system")
    print("met" if not failures else "not met: " + "; ".join(failures))
    if "--json" in argv:
        print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
