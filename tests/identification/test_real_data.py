"""Real measured data (../shared/data, or $HWPTS_DATA_DIR): skipped with a reason when absent.

Everything (orders, method, regions, partition columns, polish) is chosen on the training part
only, by held-out free-run fit (:func:`hwpts.identification.selection.select_model`: blocked
cross-validation over the whole training record, and for the actuator also the older forward
chaining); the test part is touched once, at the end. Baselines are the plain ARX fits of the data
READMEs.
"""

import warnings

import numpy as np

from hwpts.identification import PWARX
from hwpts.identification.selection import expand_grid, select_model
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
    model, table = select_model(utr, ytr, grid, {"input_delay": 1, "random_state": 0}, n_folds=5,
                                scheme="blocked", n_jobs=2)
    chosen = next(r for r in table if r.get("chosen"))
    fit = model.score(ute, yte)
    print(f"pick_and_place test fit {fit:.2f} % (ARX {arx:.2f} %), chosen {chosen}")
    assert fit >= 85.0, (fit, chosen)


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
    model, table = select_model(utr, ytr, grid, {"input_delay": 1, "random_state": 0})
    fit = model.score(ute, yte)
    print(f"actuator test fit {fit:.2f} % (ARX {arx:.2f} %), forward chaining")
    assert fit >= 50.0, (fit, [r for r in table if r.get("chosen")])
    # blocked cross-validation over the whole training record (5 blocks of ~102 samples)
    blocked, table = select_model(utr, ytr, grid, {"input_delay": 1, "random_state": 0}, n_folds=5,
                                  scheme="blocked", n_jobs=2)
    fit_blocked = blocked.score(ute, yte)
    print(f"actuator test fit {fit_blocked:.2f} % (ARX {arx:.2f} %), blocked cross-validation")
    assert fit_blocked >= 70.0, (fit_blocked, [r for r in table if r.get("chosen")])
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


def test_auto_on_actuator(real_data):
    """What `hwpts identify` does by default (segmentation auto: method, regions and the polish
    chosen by blocked cross-validation of the free-run fit on the training part)."""
    cols = read_table(real_data("hydraulic_actuator", "actuator.csv"))
    u, y = cols["u_valve_opening"][:, None], cols["y_oil_pressure"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = PWARX(3, 3, 1, n_regions="auto", segmentation="auto", random_state=0).fit(u[:512], y[:512])
    fit = model.score(u[512:], y[512:])
    print(f"actuator, auto: test fit {fit:.2f} % (plain ARX 39.9 %), {model.summary()}")
    assert fit >= 60.0, (fit, [r for r in model.selection_ if r.get("chosen")])
