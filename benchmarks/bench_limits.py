"""Where the identification targets meet the limits of the data, measured.

Two questions the zoo and real-data benchmarks leave open, answered with numbers:

1. **Boundaries learned from samples** (every PWA system of ``../shared/benchmarks/pwarx_zoo.py``):
   the oracle of the zoo knows the true partition at validation time. Here every training
   sample's true mode and the oracle's parameters are given, and only the partition is learned
   from the labelled training samples, by three classifiers of different kinds: hwpts's
   multinomial logistic classifier (``fit_linear_partition`` and ``PartitionLearner.sharpen``, what the library uses), pairwise
   linear SVMs voting one against one (a max-margin boundary per pair of modes), and the nearest
   training sample (no linear boundary at all). Whatever the classifier, a validation sample that
   falls between the last training sample of one mode and the first of another can land on either
   side; on a discontinuous map that costs the jump. The median one-step fit over the seeds is
   what an estimator that found every mode and every parameter exactly would still get.
2. **Silverbox's arrow record is partly an extrapolation test**: the default search's model
   (orders and everything chosen on the training part) has its arrow error split between the
   samples near outputs beyond the training record's range and the rest.
3. **EMPS: how much of the test score is chance**: the default search run again on the training
   output times ``1 + 1e-9 N(0, 1)`` (seeds 1, 2, ...: the choice and its test RMSE, which should
   not move), and the simulation-error polish of the chosen model's least-squares estimate
   started from that estimate times ``1 + 1e-9 N(0, 1)`` (its training fit hardly moves, its test
   RMSE does: why the search polishes only when the held-out blocks say it gains).
4. **The hydraulic actuator: can 512 training samples rank its models?** A grid of 720 models
   (na 1-6, nb 1-5, nk 0-1; one region, ``threshold`` 2-3, ``alternating`` 2-4 regions; with and
   without the polish), each fitted on the training part and scored on the test part, and scored as
   the default search scores its candidates (the mean free-run fit over its held-out blocks of the
   training part) and by its free run over the whole training part: how many reach the target, and
   how well each training-part score ranks the test fits (Spearman's rank correlation, over the
   models whose held-out runs all stayed finite). Then the same two scores on pick_and_place, over
   the candidates its default search scored on every block, each refitted on the training part.

``python -m benchmarks limits [--seeds=N] [--systems=a,b] [--no-silverbox] [--no-emps] [--no-actuator] [--draws=N]``
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

DEFAULT_SEEDS = 10
NEAR = 100  # samples on either side of an output beyond the training range count as "near" it
DRAWS = 7  # EMPS: searches on perturbed training outputs, and perturbed starts of the polish
PERTURBATION = 1e-9  # EMPS: relative size of those perturbations


def _pairwise_svm(Z, labels, Zv, n_modes, C=1e4):
    """One-vs-one linear SVM votes (scikit-learn LinearSVC per pair of modes)."""
    from sklearn.svm import LinearSVC

    votes = np.zeros((Zv.shape[0], n_modes))
    for i in range(n_modes):
        for j in range(i + 1, n_modes):
            sel = (labels == i) | (labels == j)
            if not np.any(labels == i) or not np.any(labels == j):
                continue
            clf = LinearSVC(C=C, max_iter=50_000, tol=1e-6).fit(Z[sel], (labels[sel] == i).astype(int))
            first = clf.predict(Zv)
            votes[:, i] += first
            votes[:, j] += 1 - first
    return np.argmax(votes, axis=1)


def boundary_limits(zoo, names, seeds):
    """Per system: median oracle fit and, per classifier, median one-step fit, region accuracy and
    misclassified validation samples, with the partition learned from the true training modes."""
    from sklearn.neighbors import KNeighborsClassifier
    from sklearn.preprocessing import StandardScaler

    from benchmarks.bench_zoo import learned_partition, one_step_fit, oracle_theta, validation_n

    out = {}
    for name in names:
        gen, _ = zoo.SYSTEMS[name]
        kw = {"n": 20000} if name == "pwarx_random" else {}
        rows = {k: {"fit": [], "acc": [], "wrong": []} for k in ("oracle", "logistic", "svm", "nearest")}
        for seed in seeds:
            d = gen(rng=seed, **kw)
            v = gen(n=validation_n(d), sigma=0.0, rng=10_000 + seed)
            Phi, _, M = d.regressors()
            Phi_v, Y_v, M_v = v.regressors()
            ok, ok_v = M >= 0, M_v >= 0
            Phi, M = Phi[ok], M[ok]
            Phi_v, Y_v, M_v = Phi_v[ok_v], Y_v[ok_v], M_v[ok_v]
            theta = oracle_theta(zoo, d)
            A_v = np.column_stack([Phi_v, np.ones(len(Phi_v))])
            scaler = StandardScaler().fit(Phi)
            Z, Zv = scaler.transform(Phi), scaler.transform(Phi_v)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                labels = {
                    "oracle": d.region_fn(Phi_v),
                    "logistic": learned_partition(Phi, M, d.n_modes).predict(Phi_v),
                    "svm": _pairwise_svm(Z, M, Zv, d.n_modes),
                    "nearest": KNeighborsClassifier(1).fit(Z, M).predict(Zv),
                }
            for key, lab in labels.items():
                yhat = np.einsum("ij,ij->i", A_v, theta[lab])
                rows[key]["fit"].append(one_step_fit(Y_v, yhat))
                rows[key]["acc"].append(100.0 * np.mean(lab == M_v))
                rows[key]["wrong"].append(int(np.sum(lab != M_v)))
        out[name] = {k: {m: float(np.median(v)) for m, v in r.items()} for k, r in rows.items()}
        out[name]["n_validation"] = int(len(Y_v))
    return out


def silverbox_extrapolation():
    """The default search on Silverbox's training record; its arrow error near and away from the
    outputs beyond the training range. None when the data are absent."""
    from benchmarks.bench_real import DATA, SETS, _free_run, _load
    from hwpts.identification import PWARX, PWARXSearch

    cfg = SETS["silverbox"]
    if not (DATA / cfg["train"][0]).exists():
        return None
    u, y = _load(cfg["train"], cfg["u"], cfg["y"])
    tu, ty = _load(cfg["tests"]["arrow"], cfg["u"], cfg["y"])
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, y)
    elapsed = time.perf_counter() - t0
    out, n0 = _free_run(search.best_estimator_, tu, ty, cfg["n_init"])
    err = (out - ty)[n0:] * cfg["scale"]
    yt = ty[n0:]
    beyond = (yt < y.min()) | (yt > y.max())
    near = np.convolve(beyond.astype(float), np.ones(2 * NEAR + 1), mode="same") > 0
    rms = lambda e: float(np.sqrt(np.mean(e ** 2))) if e.size else float("nan")  # noqa: E731
    tenths = [rms(part) for part in np.array_split(err, 10)]
    # what the simulation-error polish gains: the same model's least squares on both test records
    records = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = PWARX(random_state=0).set_params(**{**search.best_params_, "polish": False}).fit(u, y)
    for record, (ru, ry) in (("arrow", (tu, ty)), ("multisine", _load(cfg["tests"]["multisine"], cfg["u"], cfg["y"]))):
        records[record] = []
        for model in (plain, search.best_estimator_):
            yh, n0 = _free_run(model, ru, ry, cfg["n_init"])
            records[record].append(rms((yh - ry)[n0:] * cfg["scale"]))
    return {"records": records, "train_range": (float(y.min()), float(y.max())), "arrow_range": (float(ty.min()), float(ty.max())),
            "beyond_share": float(beyond.mean()), "near_share": float(near.mean()), "rmse": rms(err),
            "rmse_near": rms(err[near]), "rmse_away": rms(err[~near]), "tenths": tenths,
            "params": search.best_params_, "time": elapsed}


def emps_polish_spread(draws=DRAWS, eps=PERTURBATION):
    """The default search's model on EMPS and the same model polished from perturbed starts: the
    unpolished, polished and perturbed models' training free-run fit % and test RMSE [mm]; None
    when the data are absent."""
    import copy

    from benchmarks.bench_real import DATA, SETS, _free_run, _load, _score
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.polish import polish_free_run

    cfg = SETS["emps"]
    if not (DATA / cfg["train"][0]).exists():
        return None
    u, y = _load(cfg["train"], cfg["u"], cfg["y"])
    ut, yt = _load(cfg["tests"]["test"], cfg["u"], cfg["y"])
    n_init = cfg.get("n_init", 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, y)
        params = dict(search.best_params_)
        least_squares = PWARX(random_state=0).set_params(**{**params, "polish": False}).fit(u, y)

        def scores(model):
            yh, n0 = _free_run(model, ut, yt, n_init)
            return model.simulate(u, y).score(y), _score(cfg, yt, yh, n0)

        chosen = "chosen (polished)" if params.get("polish") else "chosen (not polished)"
        rows = [("least squares", *scores(least_squares)), (chosen, *scores(search.best_estimator_))]
        searches = []
        for seed in range(1, draws + 1):
            yp = y * (1.0 + eps * np.random.default_rng(seed).standard_normal(y.shape))
            again = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, yp)
            yh, n0 = _free_run(again.best_estimator_, ut, yt, n_init)
            searches.append((seed, dict(again.best_params_), _score(cfg, yt, yh, n0)))
        center, half = least_squares.divergence_band()
        for seed in range(1, draws + 1):
            rng = np.random.default_rng(seed)
            start = least_squares.theta_ * (1.0 + eps * rng.standard_normal(least_squares.theta_.shape))
            theta, _ = polish_free_run(least_squares.structure_, least_squares.partition_, start,
                                       least_squares.region_models_, u, y, center, half)
            model = copy.deepcopy(least_squares)
            model.theta_ = theta
            rows.append((f"start perturbed, seed {seed}", *scores(model)))
    return {"params": params, "rows": rows, "eps": eps, "searches": searches}


ACTUATOR_GRID = dict(output_order=range(1, 7), input_order=range(1, 6), input_delay=(0, 1),
                     method=(("average", 1), ("threshold", 2), ("threshold", 3), ("alternating", 2),
                             ("alternating", 3), ("alternating", 4)), polish=(False, True))


def _free_run_fits(cfg, model, *records):
    """The data set's score (``cfg``, as the real-data benchmark scores it) of ``model``'s free run
    of each ``(u, y)`` record, from the record's own first outputs."""
    from benchmarks.bench_real import _free_run, _score

    return [_score(cfg, y, *_free_run(model, u, y, 0)) for u, y in records]


def actuator_ranking():
    """Every model of :data:`ACTUATOR_GRID` on the hydraulic actuator: ``(params, test fit %,
    held-out fit %, training free-run fit %)`` rows (nan where a fit failed or a run diverged), and
    the run's time; None when the data are absent."""
    import itertools

    from benchmarks.bench_real import DATA, SETS, _load
    from hwpts.errors import HwptsError
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.selection.search import _evaluate

    cfg = SETS["hydraulic_actuator"]
    if not (DATA / cfg["train"][0]).exists():
        return None
    u, y = _load(cfg["train"], cfg["u"], cfg["y"])
    ut, yt = _load(cfg["tests"]["test"], cfg["u"], cfg["y"])
    g = ACTUATOR_GRID
    search = PWARXSearch(PWARX(random_state=0))
    rows = []
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for na, nb, nk, (method, count), polish in itertools.product(
                g["output_order"], g["input_order"], g["input_delay"], g["method"], g["polish"]):
            params = dict(output_order=na, input_order=nb, input_delay=nk, segmentation=method,
                          n_regions=count, polish=polish)
            test = train = held = float("nan")
            try:
                model = PWARX(random_state=0, **params).fit(u, y)
                test, train = _free_run_fits(cfg, model, (ut, yt), (u, y))
                splits = search._splits(len(y), model.structure_.max_lag)
                row = _evaluate(PWARX(random_state=0), params, u, y, splits)
                held = float("nan") if row["mean_fit_percent"] is None else row["mean_fit_percent"]
            except (HwptsError, np.linalg.LinAlgError):
                pass
            rows.append((params, test, held, train))
    return {"rows": rows, "time": time.perf_counter() - t0, "target": cfg["target"]["test"]}


def _print_actuator():
    from scipy.stats import spearmanr

    res = actuator_ranking()
    if res is None:
        print("4. the hydraulic actuator skipped: ../shared/data/hydraulic_actuator not found (set HWPTS_DATA_DIR)")
        return
    rows, target = res["rows"], res["target"]
    test = np.array([r[1] for r in rows])
    held = np.array([r[2] for r in rows])
    train = np.array([r[3] for r in rows])
    print(f"4. the hydraulic actuator: {len(rows)} models fitted on the 512 training samples ({res['time']:.0f} s)")
    scored = np.isfinite(test)
    print(f"   test free-run fit %: median {np.median(np.where(scored, test, -np.inf)):.1f}, best "
          f"{np.nanmax(test):.1f}; {int(np.sum(test >= target))} of {len(rows)} reach the target {target:.0f} % "
          f"({int(np.sum(~scored))} diverged or failed)")
    ok = scored & np.isfinite(held) & np.isfinite(train)
    rho_held = spearmanr(test[ok], held[ok]).statistic
    rho_train = spearmanr(test[ok], train[ok]).statistic
    print(f"   rank correlation with the test fit over the {int(ok.sum())} models scored everywhere: "
          f"held-out blocks (the search's score) {rho_held:.2f}, free run of the whole training part {rho_train:.2f}")
    def show(i, score, name):
        p = rows[i][0]
        print(f"   {name} {score[i]:6.2f}  test {test[i]:6.2f}  na {p['output_order']} nb {p['input_order']} "
              f"nk {p['input_delay']} {p['segmentation']} {p['n_regions']}{' polished' if p['polish'] else ''}")

    print("   the five best held-out fits and their test fits:")
    for i in np.argsort(-np.where(np.isfinite(held), held, -np.inf))[:5]:
        show(i, held, "held out")
    # the polish fits the whole-record free run itself: only least squares' runs say something there
    for polished in (False, True):
        print(f"   the three best whole-record free runs of the {'polished' if polished else 'least-squares'} models:")
        mine = np.array([r[0]["polish"] == polished for r in rows]) & np.isfinite(train)
        for i in np.argsort(-np.where(mine, train, -np.inf))[:3]:
            show(i, train, "training")


def pick_and_place_ranking():
    """The default search's fully scored candidates on pick_and_place, each refitted on the training
    part: ``(params, held-out fit %, training free-run fit %, test fit %)`` rows (nan where a run
    diverged) and the chosen parameters; None when the data are absent."""
    from benchmarks.bench_real import DATA, SETS, _load
    from hwpts.identification import PWARX, PWARXSearch

    cfg = SETS["pick_and_place"]
    if not (DATA / cfg["train"][0]).exists():
        return None
    u, y = _load(cfg["train"], cfg["u"], cfg["y"])
    ut, yt = _load(cfg["tests"]["test"], cfg["u"], cfg["y"])
    keys = ("output_order", "input_order", "input_delay", "segmentation", "n_regions")
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(u, y)
        for r in search.candidate_table():
            if r["pruned"] or r["mean_fit_percent"] is None:
                continue
            params = {**{k: r[k] for k in keys}, "polish": r.get("polish", False),
                      "output_powers": tuple(r.get("output_powers") or ())}
            model = PWARX(random_state=0).set_params(**params).fit(u, y)
            test, train = _free_run_fits(cfg, model, (ut, yt), (u, y))
            rows.append((params, r["mean_fit_percent"], train, test))
    return {"rows": rows, "chosen": search.best_params_}


def _print_pick_and_place():
    from scipy.stats import spearmanr

    res = pick_and_place_ranking()
    if res is None:
        print("   pick_and_place skipped: ../shared/data/pick_and_place not found (set HWPTS_DATA_DIR)")
        return
    rows = res["rows"]
    held, train, test = (np.array([r[k] for r in rows], float) for k in (1, 2, 3))
    ok = np.isfinite(held) & np.isfinite(train) & np.isfinite(test)
    print(f"   pick_and_place: the default search's {len(rows)} fully scored candidates, refitted on the training part;"
          f" rank correlation with the test fit over the {int(ok.sum())} whose runs stayed finite: held-out blocks "
          f"{spearmanr(test[ok], held[ok]).statistic:.2f}, free run of the whole training part "
          f"{spearmanr(test[ok], train[ok]).statistic:.2f}")
    for score, name in ((held, "held out"), (train, "training")):
        order = np.argsort(-np.where(np.isfinite(score), score, -np.inf))[:4]
        print(f"   the four best by the {name} score and their test fits: " + "; ".join(
            f"{score[i]:.2f} -> {test[i]:.2f} ({rows[i][0]['segmentation']} {rows[i][0]['n_regions']}"
            f"{' polished' if rows[i][0]['polish'] else ''})" for i in order))
    chosen = res["chosen"]
    print(f"   the search's choice: {chosen.get('segmentation')} {chosen.get('n_regions')} regions (the fewest "
          f"regions within a standard error of the best held-out fit)")


def main(argv=None) -> int:
    from benchmarks.bench_zoo import load_zoo

    argv = list(argv or [])
    seeds = DEFAULT_SEEDS
    systems = None
    draws = DRAWS
    for a in argv:
        if a.startswith("--seeds="):
            seeds = int(a.split("=", 1)[1])
        elif a.startswith("--systems="):
            systems = a.split("=", 1)[1].split(",")
        elif a.startswith("--draws="):
            draws = int(a.split("=", 1)[1])
    zoo = load_zoo()
    if zoo is None:
        print("limits: the zoo (../shared/benchmarks/pwarx_zoo.py) was not found; boundary part skipped")
    else:
        names = systems or [n for n, (gen, meta) in zoo.SYSTEMS.items()
                            if gen(rng=0, **({"n": 200} if n == "pwarx_random" else {})).theta is not None]
        unknown = [n for n in names if n not in zoo.SYSTEMS]
        if unknown:
            print(f"limits: unknown system(s) {unknown}; available: {sorted(zoo.SYSTEMS)}", file=sys.stderr)
            return 2
        t0 = time.perf_counter()
        res = boundary_limits(zoo, names, range(seeds))
        print(f"1. true modes and parameters given, partition learned from the {seeds} training sets' true modes;")
        print("   median one-step fit % on noise-free validation data [region accuracy %, misclassified samples]")
        print(f"{'system':15s} {'n val':>6s} {'oracle':>7s} {'logistic (hwpts)':>24s} {'pairwise SVM':>24s} "
              f"{'nearest sample':>24s}")
        for name, r in res.items():
            cells = [f"{r[k]['fit']:6.1f} [{r[k]['acc']:6.2f}, {r[k]['wrong']:4.0f}]" for k in ("logistic", "svm", "nearest")]
            print(f"{name:15s} {r['n_validation']:6d} {r['oracle']['fit']:7.1f} " + " ".join(f"{c:>24s}" for c in cells))
        print(f"   ({time.perf_counter() - t0:.1f} s)")
    if "--no-silverbox" not in argv:
        _print_silverbox()
    if "--no-emps" not in argv:
        _print_emps(draws)
    if "--no-actuator" not in argv:
        _print_actuator()
        _print_pick_and_place()
    return 0


def _print_emps(draws):
    em = emps_polish_spread(draws)
    if em is None:
        print("3. EMPS skipped: ../shared/data/emps not found (set HWPTS_DATA_DIR)")
        return
    def described(p):
        return (f"na {p.get('output_order')}, nb {p.get('input_order')}, nk {p.get('input_delay')}, "
                f"{p.get('segmentation')}, {p.get('n_regions')} regions{', polished' if p.get('polish') else ''}")

    p = em["params"]
    print(f"3. EMPS, the default search's model ({described(p)})")
    print(f"   the search again on the training output times 1 + {em['eps']:g} N(0, 1):")
    for seed, q, test in em["searches"]:
        same = "same choice" if q == p else described(q)
        print(f"   seed {seed}: {same}, test RMSE {test:.2f} mm")
    tests = [test for _, _, test in em["searches"]]
    if tests:
        print(f"   test RMSE over these searches: median {np.nanmedian(tests):.2f} mm, range "
              f"[{np.nanmin(tests):.2f}, {np.nanmax(tests):.2f}] mm (target 5.17 mm)")
    print(f"   the chosen model's least squares polished, started from it times 1 + {em['eps']:g} N(0, 1):")
    print(f"   {'model':28s} {'training fit %':>15s} {'test RMSE mm':>13s}")
    for name, fit, test in em["rows"]:
        print(f"   {name:28s} {fit:15.3f} {test:13.2f}")
    polished = [test for name, _, test in em["rows"] if name.startswith("start perturbed")
                or name == "chosen (polished)"]
    print(f"   polished models: test RMSE median {np.nanmedian(polished):.2f} mm, range "
          f"[{np.nanmin(polished):.2f}, {np.nanmax(polished):.2f}] mm (target 5.17 mm)")


def _print_silverbox():
    sb = silverbox_extrapolation()
    if sb is None:
        print("2. Silverbox skipped: ../shared/data/silverbox not found (set HWPTS_DATA_DIR)")
        return
    p = sb["params"]
    print(f"2. Silverbox, the default search's model (na {p.get('output_order')}, nb {p.get('input_order')}, "
          f"{p.get('segmentation')}, {p.get('n_regions')} regions"
          f"{', output powers ' + ','.join(map(str, p['output_powers'])) if p.get('output_powers') else ''}"
          f"{', polished' if p.get('polish') else ''}; "
          f"search {sb['time']:.1f} s)")
    print(f"   training outputs span [{sb['train_range'][0]:.3f}, {sb['train_range'][1]:.3f}] V, the arrow's "
          f"[{sb['arrow_range'][0]:.3f}, {sb['arrow_range'][1]:.3f}] V ({100 * sb['beyond_share']:.2f} % of its "
          f"samples beyond the training range)")
    print(f"   arrow free-run RMSE {sb['rmse']:.2f} mV: {sb['rmse_near']:.2f} mV over the {100 * sb['near_share']:.1f} % "
          f"of samples within {NEAR} samples of an output beyond the training range, {sb['rmse_away']:.2f} mV "
          f"over the rest")
    print("   RMSE per tenth of the record [mV]: " + ", ".join(f"{t:.2f}" for t in sb["tenths"]))
    if p.get("polish"):
        print("   free-run RMSE of the same model's least squares -> polished [mV]: "
              + ", ".join(f"{k} {a:.2f} -> {b:.2f}" for k, (a, b) in sb["records"].items()))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
