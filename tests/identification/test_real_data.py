"""Real measured data (../shared/data, or $HWPTS_DATA_DIR): skipped with a reason when absent.

Everything (orders, method, regions, partition columns, polish) is chosen on the training part
only, by held-out free-run fit (:class:`hwpts.identification.PWARXSearch`: blocked
cross-validation over the whole training record, and for the actuator also forward chaining,
scikit-learn's ``TimeSeriesSplit``); the test part is touched once, at the end. Baselines are the plain ARX fits of the data
READMEs.
"""

import warnings

import numpy as np

from sklearn.model_selection import TimeSeriesSplit

from hwpts.identification import PWARX, PWARXSearch
from hwpts.identification.selection import expand_grid
from hwpts.io.datasets import read_table


def test_pick_and_place(real_data):
    """400 Hz, train = first 5000, test = last 1001. Plain ARX [2 2 1]: 70.7 % (README)."""
    cols = read_table(real_data("pick_and_place", "pick_and_place_400Hz.csv"))
    u, y = cols["u"][:, None], cols["y"]
    utr, ytr, ute, yte = u[:5000], y[:5000], u[-1001:], y[-1001:]
    arx = PWARX(2, 2, 1, segmentation="average").fit(utr, ytr).score(ute, yte)
    assert abs(arx - 70.7) < 0.05
    # a small principled grid: orders, 2-3 regions, partition on y(k-1) (the contact position) or on
    # every regressor, learned (alternating) or least-squares thresholds; polish (free-run data).
    # benchmarks/bench_identification.py runs the full grid (na, nb in 1..4, polish on/off): same choice.
    grid = expand_grid({"output_order": [2, 3], "input_order": [1, 2, 3], "segmentation": ["alternating"],
                        "n_regions": [2, 3], "partition_columns": [None, ["y(k-1)"]], "polish": [True]})
    grid += expand_grid({"output_order": [2, 3], "input_order": [1, 2, 3], "segmentation": ["threshold"],
                         "n_regions": [2, 3], "polish": [True]})
    search = PWARXSearch(PWARX(input_delay=1, random_state=0), grid, cv=5, n_jobs=2, try_polish=False,
                         tolerance=0.0, n_standard_errors=0.0)  # the best mean wins outright, as GridSearchCV
    model = search.fit(utr, ytr).best_estimator_
    chosen = next(r for r in search.cv_results_ if r.get("chosen"))
    fit = model.score(ute, yte)
    print(f"pick_and_place test fit {fit:.2f} % (ARX {arx:.2f} %), chosen {chosen}")
    # The top candidates are within 0.5 points of each other in cross-validation: which one wins
    # moves with details such as dropping the regressor rows that span a held-out block, or the
    # polish's Jacobian (finite differences: 84.3 %; the sensitivity recursion: 83.5 %, the top six
    # spanning 83.3-85.6 %). So the chosen model must beat ARX by far, and the top five, refitted,
    # hold 84 % in the median. The issue-9 benchmark tracks the default search instead.
    assert fit >= 83.0, (fit, chosen)
    top = sorted((r for r in search.cv_results_ if r["mean_fit_percent"] is not None),
                 key=lambda r: -r["mean_fit_percent"])[:5]
    fits = [PWARX(input_delay=1, random_state=0, **r["params"]).fit(utr, ytr).score(ute, yte) for r in top]
    assert np.median(fits) >= 84.0, fits


def test_hydraulic_actuator(real_data):
    """Train 0-511, test 512-1023, time = sample index. Plain ARX [3 2 1]: 39.9 % (README)."""
    cols = read_table(real_data("hydraulic_actuator", "actuator.csv"))
    u, y = cols["u_valve_opening"][:, None], cols["y_oil_pressure"]
    utr, ytr, ute, yte = u[:512], y[:512], u[512:], y[512:]
    arx = PWARX(3, 2, 1, segmentation="average").fit(utr, ytr).score(ute, yte)
    assert abs(arx - 39.9) < 0.05
    grid = []
    for na, nb in [(3, 2), (3, 3)]:
        grid += expand_grid({"output_order": [na], "input_order": [nb],
                             "segmentation": ["average", "kmeans", "clustering", "alternating"],
                             "n_regions": [2, 3], "polish": [False, True]})
    base = PWARX(input_delay=1, random_state=0)
    forward = PWARXSearch(base, grid, cv=TimeSeriesSplit(n_splits=2, test_size=128), try_polish=False)
    model = forward.fit(utr, ytr).best_estimator_
    fit = model.score(ute, yte)
    print(f"actuator test fit {fit:.2f} % (ARX {arx:.2f} %), forward chaining")
    assert fit >= 50.0, (fit, forward.best_params_)
    # blocked cross-validation over the whole training record (5 blocks of ~102 samples). The blocks
    # hardly rank the best candidates (held-out fits 24-32 % for the top eight, whose test-part
    # scores span 47-79 %): the assertion is that the choice is a working PWA model well above ARX.
    blocked = PWARXSearch(base, grid, cv=5, n_jobs=2, try_polish=False).fit(utr, ytr)
    fit_blocked = blocked.score(ute, yte)
    print(f"actuator test fit {fit_blocked:.2f} % (ARX {arx:.2f} %), blocked cross-validation")
    assert fit_blocked >= 55.0, (fit_blocked, blocked.best_params_)
    # a naive k-means PWARX is not chosen when it diverges or fits worse
    assert model.segmentation != "kmeans" or np.isfinite(fit)


def test_naive_kmeans_on_actuator_is_reported_not_scored(real_data):
    cols = read_table(real_data("hydraulic_actuator", "actuator.csv"))
    u, y = cols["u_valve_opening"][:, None], cols["y_oil_pressure"]
    results = []
    for s in (2, 3, 4):
        m = PWARX(3, 2, 1, n_regions=s, segmentation="kmeans", random_state=0).fit(u[:512], y[:512])
        sim = m.simulate(u[512:], y[512:])
        results.append((sim.diverged, sim.reason))
        if sim.diverged:
            assert "left the band" in sim.reason
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                assert np.isnan(m.score(u[512:], y[512:]))


def test_default_search_on_actuator(real_data):
    """What `hwpts identify --na 3 --nb 3` does (method, regions and the polish chosen by blocked
    cross-validation of the free-run fit on the training part)."""
    cols = read_table(real_data("hydraulic_actuator", "actuator.csv"))
    u, y = cols["u_valve_opening"][:, None], cols["y_oil_pressure"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        search = PWARXSearch(PWARX(3, 3, 1, random_state=0)).fit(u[:512], y[:512])
    fit = search.score(u[512:], y[512:])
    print(f"actuator, default search: test fit {fit:.2f} % (plain ARX 39.9 %), {search.best_params_}")
    assert fit >= 60.0, (fit, search.best_params_)


def test_default_search_on_emps(real_data):
    """EMPS (../shared/data/emps/README.md): everything chosen on the training record by the default
    search, free run of the test record from its first 20 samples. Plain ARX 22.1 mm; the published
    polynomial NARX 5.17 mm. Measured 2026-11-25: with the threshold block costs computed in an
    orthonormal basis (accurate least squares), the search chooses na 4, nb 1, nk 1, threshold,
    6 regions, unpolished (held-out fit 98.3 %), 3.65 mm on the test record. Before, the block costs
    on the raw, nearly collinear lagged positions were 10-60x the true residual sums, the cuts
    landed elsewhere, and only a polished 8-region model (4.75 mm, one draw of a polish whose
    result spreads over 3.6-123 mm) beat the target. The test asks that the default beat the
    published polynomial NARX."""
    train = read_table(real_data("emps", "emps_train.csv"))
    test = read_table(real_data("emps", "emps_test.csv"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        search = PWARXSearch(PWARX(random_state=0), orders="auto").fit(train["u"][:, None], train["y"])
        model = search.best_estimator_
        u, y = test["u"][:, None], test["y"]
        sim = model.simulate(u[20 - model.structure_.max_lag:], y[20 - model.structure_.max_lag:])
    assert not sim.diverged
    rmse_mm = 1000 * float(np.sqrt(np.mean((y[20:] - sim.output[model.structure_.max_lag:]) ** 2)))
    print(f"EMPS default search: test RMSE {rmse_mm:.2f} mm, {search.best_params_}")
    assert search.best_params_["segmentation"] == "threshold"
    assert rmse_mm < 5.17, (rmse_mm, search.best_params_)
