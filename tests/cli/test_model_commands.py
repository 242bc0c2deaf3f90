"""``hwpts identify | validate | predict`` in-process: outputs, and one clear line on bad input."""

import json

import numpy as np
import pytest
from scipy.io import savemat

from hwpts.cli import main
from hwpts.identification.synthetic import make_system
from hwpts.io.datasets import write_csv


@pytest.fixture
def data_csv(tmp_path):
    d = make_system(5, rng=0, n=1500)
    path = tmp_path / "s5.csv"
    write_csv(path, {"time_s": np.arange(1500) * 0.01, "u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    return path


IDENTIFY = ["--input", "u1", "--input", "u2", "--output", "y", "--na", "2", "--nb", "2"]


@pytest.fixture
def model_json(tmp_path, data_csv, capsys):
    out = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "alternating", "--regions", "3",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    return out


def test_identify_prints_summary_and_writes_model(tmp_path, data_csv, capsys):
    out = tmp_path / "m.json"
    code = main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "alternating", "--regions", "3",
                 "--seed", "1", "--out", str(out)])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and out.exists()
    assert summary["n_regions"] == 3 and summary["segmentation"] == "alternating"
    # the method and count told, na searched: the orders ranked as ARX models, then that method alone at that count
    assert main(["identify", str(data_csv), *IDENTIFY[:6], "--nb", "2", "--segmentation", "alternating",
                 "--regions", "3", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n_regions"] == 3 and summary["segmentation"] == "alternating"
    assert {(r["segmentation"], r["n_regions"]) for r in summary["candidates"]
            if r["stage"] != "powers"} == {("average", 1), ("alternating", 3)}
    assert summary["train_fit_percent"] > 50 and summary["train_one_step_fit_percent"] > 80
    assert json.loads(out.read_text())["schema"] == "hwpts.pwarx/1"
    # system 5 switches on y(k-1) - u2(k-1): the learned partition keeps those two columns
    assert summary["partition_columns"] == ["y(k-1)", "u2(k-1)"]
    assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "alternating", "--regions", "3",
                 "--seed", "1", "--all-partition-columns", "--out", str(out)]) == 0
    assert "partition_columns" not in json.loads(capsys.readouterr().out)


def test_validate_json_and_text(model_json, data_csv, capsys):
    assert main(["validate", str(model_json), str(data_csv), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    for key in ("fit_percent", "one_step_fit_percent", "rmse", "n_samples"):
        assert key in result
    assert result["n_samples"] == 1500 and result["diverged"] is False
    assert main(["validate", str(model_json), str(data_csv), "--rows", "500:"]) == 0
    text = capsys.readouterr().out
    assert "free-run fit:" in text and "1000 samples" in text


@pytest.mark.parametrize("mode", ["simulate", "one-step"])
def test_predict_writes_csv(model_json, data_csv, tmp_path, capsys, mode):
    out = tmp_path / "p.csv"
    assert main(["predict", str(model_json), str(data_csv), "--out", str(out), "--mode", mode]) == 0
    header = out.read_text().splitlines()[0]
    assert header == "time_s,u1,u2,y,y_predicted,region"
    assert len(out.read_text().splitlines()) == 1501


def test_hyperplane_identify(tmp_path, data_csv, capsys):
    out = tmp_path / "h.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--hyperplane", "1,-1,-0.6@y(k-1),u2(k-1)",
                 "--hyperplane", "1,-1,0.4@y(k-1),u2(k-1)", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["segmentation"] == "hyperplane" and summary["n_regions"] == 3
    assert summary["train_one_step_fit_percent"] > 90


def _expect_error(capsys, argv, match, not_written=None):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hwpts: error:"), err
    assert "Traceback" not in err
    assert match in lines[0], lines[0]
    if not_written is not None:
        assert not not_written.exists()
        assert not list(not_written.parent.glob(f".{not_written.name}*"))  # no temporary left


def test_unknown_column(tmp_path, data_csv, capsys):
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(data_csv), "--input", "nope", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], "no column(s) ['nope']; available columns are", out)


def test_an_unknown_column_lists_the_files_columns(tmp_path, capsys):
    # the message listed only the requested columns it had found (u missing from the list below)
    path = tmp_path / "d.csv"
    path.write_text("t,u,y\n" + "".join(f"{k},{k % 3},{k % 5}\n" for k in range(50)))
    _expect_error(capsys, ["identify", str(path), "--input", "x", "--output", "y", "--out", str(tmp_path / "m.json")],
                  "no column(s) ['x']; available columns are ['t', 'u', 'y']")
    headless = tmp_path / "h.csv"
    headless.write_text("".join(f"{k},{k + 0.5}\n" for k in range(50)))
    _expect_error(capsys, ["identify", str(headless), "--input", "u", "--output", "y", "--out", str(tmp_path / "m.json")],
                  "a header row such as u,y")


def test_too_few_samples(tmp_path, capsys):
    path = tmp_path / "short.csv"
    rng = np.random.default_rng(0)
    write_csv(path, {"a": rng.random(7), "b": rng.random(7), "y": rng.random(7)})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "a", "--input", "b", "--output", "y", "--na", "5",
                           "--nb", "4", "--nk", "0", "--out", str(out)],
                  "na=5, nb=4, nk=0 needs at least 19 samples (5 initial conditions + 14 parameters); "
                  f"{str(path)!r} has 7 rows", out)


def test_nan_in_data(tmp_path, capsys):
    path = tmp_path / "nan.csv"
    path.write_text("u,y\n" + "\n".join(f"{i % 7},{i % 5}" for i in range(30)) + "\nnan,1\n")
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], "non-finite value (NaN, inf or an empty cell) at row 30", out)


def test_constant_input(tmp_path, capsys):
    path = tmp_path / "c.csv"
    rng = np.random.default_rng(0)
    write_csv(path, {"u": np.ones(50), "v": rng.random(50), "y": rng.random(50)})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "v", "--input", "u", "--output", "y", "--na", "1",
                           "--nb", "1", "--segmentation", "average", "--out", str(out)], "input 'u' is constant", out)


def test_region_left_empty(tmp_path, data_csv, capsys):
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(data_csv), *IDENTIFY, "--hyperplane", "1,5", "--out", str(out)],
                  "leave region(s) [2] of 2 empty", out)


def test_model_of_another_schema_and_tampered(tmp_path, model_json, data_csv, capsys):
    doc = json.loads(model_json.read_text())
    other = tmp_path / "other.json"
    other.write_text(json.dumps({**doc, "schema": "hwpts.reproduce/1"}))
    _expect_error(capsys, ["validate", str(other), str(data_csv)], "is not 'hwpts.pwarx/1'")
    doc["regions"][0]["theta"][0] += 1e-9
    tampered = tmp_path / "tampered.json"
    tampered.write_text(json.dumps(doc))
    out = tmp_path / "p.csv"
    _expect_error(capsys, ["predict", str(tampered), str(data_csv), "--out", str(out)], "checksum mismatch", out)


def test_mat_without_the_variable(tmp_path, capsys):
    path = tmp_path / "d.mat"
    rng = np.random.default_rng(0)
    savemat(path, {"u": rng.random((40, 1)), "p": rng.random((40, 1))})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], "no column(s) ['y']; available columns are ['p', 'u']", out)


def test_mat_with_a_variable_of_text_says_so(tmp_path, capsys):
    """A text or cell variable was said to be missing ('no column(s) ['u']') although the file has it."""
    path = tmp_path / "d.mat"
    savemat(path, {"u": "hello", "y": np.arange(40.0)})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], "the variable 'u' holds no numbers (text, a cell array or a struct)",
                  out)


@pytest.mark.parametrize("value, said", [(np.eye(3), "is a square 3x3 matrix (its samples could run down or across)"),
                                         (np.zeros((0, 0)), "is empty (0x0)"),
                                         (np.zeros((40, 2, 2)), "is a 3-D array (40x2x2)")])
def test_mat_variable_that_is_no_vector_says_what_it_is(tmp_path, capsys, value, said):
    """A square, empty or 3-D output variable was said to be missing although the file has it."""
    path = tmp_path / "d.mat"
    savemat(path, {"u": np.arange(40.0), "y": value})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], f"the variable 'y' {said}; save each signal as a numeric vector", out)


def test_mat_with_the_variables_works(tmp_path, capsys):
    path = tmp_path / "d.mat"
    d = make_system(5, rng=2, n=400)
    savemat(path, {"u1": d.inputs[:, :1], "u2": d.inputs[:, 1:], "y": d.output[:, None]})
    out = tmp_path / "m.json"
    assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["n_regions"] == 1


@pytest.mark.parametrize("name, scale", [("Time", 1.0), ("TIME_S", 1.0), ("time_ms", 1e3), ("t_us", 1e6)])
def test_a_time_column_by_another_usual_name_is_the_time_axis(tmp_path, capsys, name, scale):
    """A time column named Time (MATLAB and LabVIEW exports) or t_ms was read past: a model of
    100 Hz data was scored on data at 1 kHz without a word, and a model fitted on such a file knew
    no sample time."""
    d = make_system(5, rng=2, n=400)
    signals = {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output}
    path, model = tmp_path / "d.csv", tmp_path / "m.json"
    write_csv(path, {name: scale * 0.01 * np.arange(400), **signals})
    assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(model)]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] == pytest.approx(0.01)
    fast = tmp_path / "fast.csv"
    write_csv(fast, {name: scale * 0.001 * np.arange(400), **signals})
    _expect_error(capsys, ["validate", str(model), str(fast)], "sample time 0.001 s (1000 Hz) differs from the model's")


def test_names_like_a_time_that_are_no_time_axis_are_left_alone(tmp_path, capsys):
    """T_h (a temperature), t_min (a minimum) and a time_min column that does not increase are
    signals, not the time axis (a T_h column made such files fail as 'time must be increasing')."""
    d = make_system(5, rng=2, n=400)
    rng = np.random.default_rng(0)
    path = tmp_path / "d.csv"
    write_csv(path, {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output, "T_h": 20 + rng.random(400),
                     "t_min": rng.random(400), "time_min": rng.random(400), "timestamp": 1.7e12 + 10 * np.arange(400)})
    assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(tmp_path / "m.json")]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] is None


def test_zero_region_with_a_method_of_its_own_count(tmp_path, data_csv, capsys):
    """zscore always makes 2 regions: --zero-region 2 needed --regions 2 as well."""
    out = tmp_path / "z.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "zscore", "--zero-region", "2",
                 "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert [r["model"] for r in summary["regions"]] == ["affine", "zero"]


def test_zscore_regions_are_classified_so_the_partition_column_options_apply(tmp_path, data_csv, capsys):
    """zscore labels the rows by its rule and a classifier draws the boundary: ``--partition-column``
    and ``--all-partition-columns`` act on it (the first was refused as for a given partition, and the
    second would have been, by a review's first fix), while ``threshold`` draws its own."""
    from hwpts.io.models import load_model

    models = {}
    for name, extra in (("columns", ["--partition-column", "y(k-1)"]), ("all", ["--all-partition-columns"]), ("", [])):
        out = tmp_path / f"z{name}.json"
        assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "zscore", *extra, "--out", str(out)]) == 0
        models[name] = load_model(out).partition_
    capsys.readouterr()
    H = models["columns"].H[0]
    assert np.count_nonzero(H[:, 1:]) == 0 and np.count_nonzero(H[:, 0]) > 0  # y(k-1) alone
    assert not np.allclose(models["columns"].H[0], models["all"].H[0])
    assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "threshold", "--regions", "2",
                 "--all-partition-columns", "--out", str(tmp_path / "t.json")]) == 2


def test_mat_sample_time_variable(tmp_path, capsys):
    """A .mat file's scalar Ts (as MATLAB's iddata) is its sample time when it has no time column;
    a time column that disagrees with it, or a Ts that is no period, is refused."""
    d = make_system(5, rng=2, n=400)
    signals = {"u1": d.inputs[:, :1], "u2": d.inputs[:, 1:], "y": d.output[:, None]}
    path, out = tmp_path / "d.mat", tmp_path / "m.json"
    savemat(path, {**signals, "Ts": np.array([[0.05]])})
    assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] == 0.05
    assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--time", "none",
                 "--out", str(tmp_path / "n.json")]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] is None
    out = tmp_path / "refused.json"
    savemat(path, {**signals, "Ts": np.array([[0.05]]), "t": 0.1 * np.arange(400)[:, None]})
    _expect_error(capsys, ["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(out)],
                  "the time column 't' is sampled every 0.1 s but the variable 'Ts' says 0.05 s", out)
    savemat(path, {**signals, "dt": np.array([[0.0]])})
    _expect_error(capsys, ["identify", str(path), *IDENTIFY, "--segmentation", "average", "--out", str(out)],
                  "the variable 'dt' is taken as the sample time in seconds; expected a positive number, got 0", out)


def test_bad_arguments(tmp_path, data_csv, capsys):
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(data_csv), *IDENTIFY, "--segmentation", "nope", "--out", str(out)],
                  "invalid choice: 'nope'", out)
    _expect_error(capsys, ["identify", str(data_csv), *IDENTIFY, "--hyperplane", "a,b", "--out", str(out)],
                  "hyperplane 'a,b': expected numbers", out)
    _expect_error(capsys, ["identify", str(data_csv), *IDENTIFY, "--time", "t", "--out", str(out)],
                  "no time column 't'", out)
    _expect_error(capsys, ["identify", str(data_csv), *IDENTIFY, "--regions", "x", "--out", str(out)],
                  "--regions expects an int", out)


def test_diverging_free_run_writes_no_file(tmp_path, data_csv, capsys):
    from hwpts.identification import PWARX
    from hwpts.identification.partition import RegionPartition
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.io.models import save_model

    st = RegressorStructure.create(2, 2, 1, 2, input_names=["u1", "u2"], output_name="y")
    theta = np.zeros((1, 7))
    theta[0, 0] = 1.5
    theta[0, 2] = 1.0
    model = PWARX.from_parts(st, RegionPartition.single(6), theta, output_range=(-2.0, 2.0),
                             input_ranges=[[-1, 1], [-1, 1]])
    path = tmp_path / "unstable.json"
    save_model(model, path)
    assert main(["validate", str(path), str(data_csv), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["diverged"] is True and result["fit_percent"] is None and "left the band" in result["reason"]
    out = tmp_path / "p.csv"
    _expect_error(capsys, ["predict", str(path), str(data_csv), "--out", str(out)], "no file written", out)


def test_identify_chooses_the_orders_and_says_why(tmp_path, capsys):
    """Without --na/--nb/--nk the orders are chosen on the data: an ARX [2 2 1] system is recognised."""
    rng = np.random.default_rng(0)
    u = rng.standard_normal(1500)
    y = np.zeros(1500)
    for k in range(2, 1500):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + u[k - 1] + 0.5 * u[k - 2] + 0.05 * rng.standard_normal()
    path = tmp_path / "arx.csv"
    write_csv(path, {"u": u, "y": y})
    out = tmp_path / "m.json"
    assert main(["identify", str(path), "--input", "u", "--output", "y", "--segmentation", "average",
                 "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    choice = summary["choice"]
    assert (choice["na"], choice["nb"], choice["nk"]) == (2, [2], [1])
    assert "held-out blocks" in choice["why"] and choice["n_candidates"] == len(summary["candidates"]) == 40
    assert sum(bool(r.get("chosen")) for r in summary["candidates"]) == 1
    assert choice["scoring"] == "free-run" and "one-step" not in choice["why"]
    assert choice["orders"] is None  # one method and count: the grid of orders ranks itself


def test_the_librarys_default_search_is_the_commands_default(tmp_path, capsys):
    """``PWARXSearch(PWARX())`` and ``hwpts identify`` without settings choose the same model: the
    orders a PWARX leaves None are the ones the search chooses, as those --na/--nb/--nk leave out."""
    from hwpts.identification import PWARX, PWARXSearch

    rng = np.random.default_rng(3)
    u = rng.uniform(-1, 1, 600)
    y = np.zeros(600)
    for k in range(2, 600):
        a = 0.8 if y[k - 1] > 0 else 0.3  # two modes switching on y(k-1)
        y[k] = a * y[k - 1] - 0.2 * y[k - 2] + u[k - 1] + 0.5 * u[k - 2] + 0.02 * rng.standard_normal()
    path = tmp_path / "pwa.csv"
    write_csv(path, {"u": u, "y": y})
    out = tmp_path / "m.json"
    assert main(["identify", str(path), "--input", "u", "--output", "y", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert PWARX().get_params()["output_order"] is None
    search = PWARXSearch(PWARX(random_state=0)).fit(u[:, None], y)
    best = search.best_estimator_
    st = best.structure_
    assert (summary["choice"]["na"], summary["choice"]["nb"], summary["choice"]["nk"]) == (st.na, list(st.nb),
                                                                                           list(st.nk))
    assert summary["segmentation"] == best.segmentation and summary["n_regions"] == best.n_regions_
    assert len(summary["candidates"]) == len(search.cv_results_)
    assert summary["train_fit_percent"] == pytest.approx(best.score(u[:, None], y), abs=1e-3)
    # orders given to the estimator are kept, the input delay then 1 (as --na 2 --nb 2)
    given = PWARXSearch(PWARX(output_order=2, input_order=2, random_state=0), try_polish=False,
                        max_regions=2).fit(u[:, None], y)
    assert {(r["params"].get("output_order"), r["params"].get("input_delay")) for r in given.cv_results_} == {(None, None)}
    assert given.best_estimator_.structure_.nk == (1,)


def test_a_partition_column_of_a_long_lag_carries_the_orders_that_hold_it(tmp_path, capsys):
    """``--partition-column "u(k-3)"`` with the orders searched: the ARX models (no partition)
    rank the orders, and the orders carried to the regions are those whose regressor holds the
    column (three carried orders without it made every candidate fail)."""
    rng = np.random.default_rng(2)
    u = rng.uniform(-1, 1, 600)
    y = np.zeros(600)
    for k in range(3, 600):
        y[k] = 0.6 * y[k - 1] + u[k - 1] + (0.8 if u[k - 3] > 0 else -0.3) * u[k - 2] + 0.01 * rng.standard_normal()
    path = tmp_path / "lag.csv"
    write_csv(path, {"u": u, "y": y})
    assert main(["identify", str(path), "--input", "u", "--output", "y", "--regions", "2",
                 "--partition-column", "u(k-3)", "--out", str(tmp_path / "m.json")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert not [r for r in summary["candidates"] if r["error"]]
    assert summary["choice"]["nk"][0] + summary["choice"]["nb"][0] - 1 >= 3  # u(k-3) in the regressor


def test_identify_says_how_it_ranked_the_orders(tmp_path, capsys):
    """Three modes behind oblique boundaries: no ARX model explains them, a nearest-neighbour
    predictor does, and the orders it predicts best with (the true 1/1/1) are chosen; the summary
    says so."""
    rng = np.random.default_rng(0)
    n = 1000
    u = rng.uniform(-2, 2, n)
    y = np.zeros(n)
    theta = np.array([[0.5, 1.0, 0.0], [0.8, -0.5, 0.3], [0.2, 0.7, -0.4]])
    for k in range(1, n):
        mode = 0 if y[k - 1] + u[k - 1] < -0.5 else (1 if y[k - 1] - u[k - 1] < 0.5 else 2)
        y[k] = theta[mode] @ [y[k - 1], u[k - 1], 1.0] + 0.05 * rng.standard_normal()
    path = tmp_path / "oblique.csv"
    write_csv(path, {"u": u, "y": y})
    out = tmp_path / "m.json"
    assert main(["identify", str(path), "--input", "u", "--output", "y", "--out", str(out)]) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    orders = choice["orders"]
    assert orders["ranked_by"] == "neighbours" and orders["neighbour_one_step_percent"] > orders["arx_one_step_percent"] + 10
    assert "no ARX model explains the data" in orders["why"]
    assert (choice["na"], choice["nb"], choice["nk"]) == (1, [1], [1])


def test_identify_scoring(tmp_path, capsys):
    """A chaotic two-mode map (the tent map): no ARX free run explains the data, so the one-step
    fit ranks the candidates and the summary says so; --scoring free-run keeps the ARX model;
    a bad --scoring is one line and exit 2."""
    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, 1500)
    y = np.zeros(1500)
    for k in range(1, 1500):
        y[k] = 1.0 - 1.8 * abs(y[k - 1]) + 0.1 * u[k - 1] + 0.01 * rng.standard_normal()
    path = tmp_path / "tent.csv"
    write_csv(path, {"u": u, "y": y})
    out = tmp_path / "m.json"
    base = ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1", "--out", str(out)]
    assert main(base) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["scoring"] == "one-step" and choice["n_regions"] == 2
    assert "ranked by the one-step fit because no ARX model's held-out free run reached 10 % fit" in choice["why"]
    assert main(base + ["--scoring", "free-run"]) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["scoring"] == "free-run" and choice["n_regions"] == 1
    out.unlink()
    _expect_error(capsys, base + ["--scoring", "r2"], "--scoring", out)


def test_identify_shared_modes(tmp_path, capsys):
    """Two modes sharing their parameters over opposite quadrants: identify tries the switched
    segmentation and says why (summary choice.shared_modes); --shared-modes off does not; a bad
    value is one line and exit 2."""
    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, (1500, 2))
    y = np.where(u[:, 0] * u[:, 1] > 0, 1 + 2 * u[:, 0] - u[:, 1], -1 - u[:, 0] + 3 * u[:, 1])
    y = y + 0.01 * rng.standard_normal(1500)
    path = tmp_path / "xor.csv"
    write_csv(path, {"u1": u[:, 0], "u2": u[:, 1], "y": y})
    out = tmp_path / "m.json"
    base = ["identify", str(path), "--input", "u1", "--input", "u2", "--output", "y", "--na", "0", "--nb", "1",
            "--nk", "0", "--out", str(out)]
    assert main(base) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["segmentation"] == "switched" and choice["n_regions"] >= 4
    shared = choice["shared_modes"]
    assert shared["tried"] and shared["gate_open"] and shared["from_modes"] == 2
    assert shared["switched_in_sample_fits_percent"]["2"] > 98 > 70 > shared["best_heldout_one_step_fit_percent"]
    assert main(base + ["--shared-modes", "off"]) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["segmentation"] != "switched" and choice["shared_modes"]["tried"] is False
    out.unlink()
    _expect_error(capsys, base + ["--shared-modes", "maybe"], "--shared-modes", out)


def test_search_bad_inputs_give_one_line(tmp_path, data_csv, capsys):
    path = tmp_path / "short.csv"
    rng = np.random.default_rng(0)
    write_csv(path, {"a": rng.random(25), "y": rng.random(25)})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "a", "--output", "y", "--out", str(out)],
                  "25 samples are too few to choose a model", out)
    short = tmp_path / "s300.csv"
    d = make_system(5, rng=0, n=300)
    write_csv(short, {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    _expect_error(capsys, ["identify", str(short), *IDENTIFY, "--segmentation", "alternating", "--regions", "50",
                           "--out", str(out)], "--regions 50: expected at most 14 for 300 samples", out)


def test_regions_given_method_auto_chooses_among_the_default_methods(tmp_path, data_csv, capsys):
    """--regions S without --segmentation: the adaptive search at S regions only (``n_regions=S``):
    each default method with S regions is scored on the held-out blocks beside the single ARX
    model, which only ranks the orders, and the choice has S regions (it fitted the library's
    clustering before, and with the orders left open it stopped on "segmentation 'auto' is a model
    search"; then a grid over every order and method, 38 s on Silverbox where this takes 4 s)."""
    from hwpts.identification.selection import DEFAULT_METHODS

    out = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--regions", "3", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["segmentation"] in (*DEFAULT_METHODS, "threshold-alternating") and summary["n_regions"] == 3
    raced = {r["segmentation"] for r in summary["candidates"] if r["stage"] == "regions" and r["n_regions"] == 3}
    assert set(DEFAULT_METHODS) <= raced
    assert {r["n_regions"] for r in summary["candidates"]} == {1, 3}
    assert "chosen among those with the 3 region(s) asked for" in summary["choice"]["why"]
    rows = tmp_path / "short.csv"
    d = make_system(5, rng=0, n=400)
    write_csv(rows, {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    assert main(["identify", str(rows), "--input", "u1", "--input", "u2", "--output", "y", "--regions", "2",
                 "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["segmentation"] in (*DEFAULT_METHODS, "threshold-alternating") and summary["n_regions"] == 2
    assert main(["identify", str(data_csv), *IDENTIFY, "--regions", "1", "--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["segmentation"] == "average"


def test_zero_region_with_a_count_and_the_orders_open(tmp_path, data_csv, capsys):
    """--zero-region numbers regions of the count given: every candidate has that count (a grid),
    not the adaptive search's single ARX models, which failed on the zero modes' count."""
    out = tmp_path / "z.json"
    assert main(["identify", str(data_csv), "--input", "u1", "--input", "u2", "--output", "y", "--nk", "1",
                 "--regions", "2", "--zero-region", "2", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n_regions"] == 2 and summary["choice"]["scoring"] == "free-run"
    assert {r["n_regions"] for r in summary["candidates"]} == {2}


def test_hyperplane_with_a_negative_first_coefficient(tmp_path, data_csv, capsys):
    """The documented form for a negative first coefficient: --hyperplane=-1,0,0.2."""
    out = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--hyperplane=-1,0,0.2", "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["segmentation"] == "hyperplane" and summary["n_regions"] == 2


def test_negative_values_given_as_a_separate_token(tmp_path, data_csv, capsys):
    """``--hyperplane -1,0,0.2`` (argparse alone takes -1,0,0.2 for an option) gives the same model
    as the documented ``--hyperplane=-1,0,0.2``; ``--rows -300:`` the same rows as ``--rows=-300:``."""
    attached, spaced = tmp_path / "a.json", tmp_path / "s.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--hyperplane=-1,0,0.2", "--rows=-300:", "--out", str(attached)]) == 0
    first = json.loads(capsys.readouterr().out)
    assert main(["identify", str(data_csv), *IDENTIFY, "--hyperplane", "-1,0,0.2", "--rows", "-300:", "--out", str(spaced)]) == 0
    second = json.loads(capsys.readouterr().out)
    assert first["n_samples"] == second["n_samples"] == 300
    assert json.loads(attached.read_text())["regions"] == json.loads(spaced.read_text())["regions"]


def test_cli_segmentation_names_match_the_registry():
    """`hwpts identify --segmentation` lists the registry's names without importing the library."""
    from hwpts.commands.model import SEGMENTATION_NAMES
    from hwpts.identification.segmentation import SEGMENTATION_METHODS

    assert sorted(SEGMENTATION_NAMES) == sorted(SEGMENTATION_METHODS)


def test_identify_help_names_the_methods_auto_chooses_among(capsys):
    """The help of --segmentation names the search's default methods (it named clustering too,
    which the default search does not try)."""
    from hwpts.cli import main
    from hwpts.identification.selection import DEFAULT_METHODS

    try:
        main(["identify", "--help"])
    except SystemExit:
        pass
    text = " ".join(capsys.readouterr().out.split())
    assert "chosen on the data among " + ", ".join(DEFAULT_METHODS) + " (and threshold-" in text
    assert "(and threshold-alternating where a threshold split" in text.replace("- ", "-")  # help wraps at hyphens


def test_help_does_not_import_the_numerical_libraries():
    import subprocess
    import sys

    code = ("import sys; from hwpts.cli import main\n"
            "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
            "heavy = [m for m in ('sklearn', 'scipy', 'numba', 'matplotlib') if m in sys.modules]\n"
            "print(heavy); sys.exit(1 if heavy else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_identify_reports_a_cascade_of_region_warnings_in_one_line():
    """The summary's ``warnings``: drops that follow each other (26 -> 11 -> 8 regions) in one line,
    several ill-conditioned regions in one line, at the place of the first; other messages as they
    came, each once; drops that do not chain (two fits) kept apart."""
    import warnings as w

    from hwpts.commands.model import _warning_lines
    from hwpts.identification import RegionWarning

    def caught(*messages):
        with w.catch_warnings(record=True) as got:
            w.simplefilter("always")
            for m in messages:
                w.warn(m)
        return [g.message for g in got]

    def dropped(a, b):
        return RegionWarning(f"{a - b} of {a} regions received no training sample and were dropped; "
                             f"the model has {b} regions", "dropped", before=a, after=b)

    def ill(region, cond):
        return RegionWarning(f"region {region}: ill-conditioned {cond}", "ill_conditioned", region=region,
                             condition=cond)

    lines = _warning_lines(caught(dropped(26, 11), UserWarning("other"), ill(4, 6.07e16), dropped(11, 8),
                                  ill(2, 1.26e16), UserWarning("other")))
    assert lines == [
        "18 of 26 regions received no training sample and were dropped (26 -> 11 -> 8); the model has 8 regions",
        "other",
        "regions 2, 4: least squares is ill-conditioned (condition numbers 1.26e+16, 6.07e+16); their inputs "
        "may not be exciting enough, consider a ridge penalty",
    ]
    assert _warning_lines(caught(dropped(5, 4))) == [str(dropped(5, 4))]  # one: as it was said
    assert _warning_lines(caught(dropped(5, 4), dropped(3, 2))) == [str(dropped(5, 4)), str(dropped(3, 2))]


def test_identify_estimates_a_dead_time_when_nk_is_not_given(tmp_path, capsys):
    """Without --nk (and without both --na and --nb, which default --nk to 1) the delay is estimated
    (as MATLAB's delayest): a 5-sample dead time, beyond the grid's delays 0 and 1, is found and
    said; with --nk given nothing is estimated."""
    rng = np.random.default_rng(0)
    n = 1200
    u = rng.uniform(-1, 1, n)
    y = np.zeros(n)
    for k in range(7, n):
        drive = 0.6 * u[k - 5] + 0.3 * u[k - 6]
        y[k] = (1.2 * y[k - 1] - 0.5 * y[k - 2] + drive if y[k - 1] > 0
                else 0.9 * y[k - 1] - 0.3 * y[k - 2] + 0.4 * drive + 0.1) + 0.02 * rng.standard_normal()
    path = tmp_path / "dead_time.csv"
    write_csv(path, {"u": u, "y": y})
    out = tmp_path / "m.json"
    base = ["identify", str(path), "--input", "u", "--output", "y", "--nb", "2", "--regions", "2",
            "--out", str(out)]
    assert main(base) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["input_delays"]["estimated"] == [5] and choice["input_delays"]["tried"] == [5, 4]
    assert "dead time" in choice["input_delays"]["why"] and choice["nk"] == [5]
    out.unlink()
    assert main(base + ["--nk", "1"]) == 0
    assert json.loads(capsys.readouterr().out)["choice"]["input_delays"] is None
    out.unlink()
    # a partition column among the lags of the estimated delay is a valid name (checked after it)
    assert main(base + ["--partition-column", "u(k-6)"]) == 0
    assert json.loads(capsys.readouterr().out)["choice"]["nk"] in ([5], [4])


def _duffing_csv(path, n, seed, noise=0.0):
    """A hardening spring (a cube of the output, Silverbox's physics) as ``u,y`` CSV at ``path``."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, n)
    y = np.zeros(n)
    for k in range(2, n):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] - 0.2 * y[k - 1] ** 3 + 0.5 * u[k - 1]
    y += noise * rng.standard_normal(n)
    write_csv(path, {"u": u, "y": y})
    return path


def test_identify_output_powers(tmp_path, capsys):
    """``--output-powers``: ``auto`` lets the search try 2,3 and say so, on a hardening spring it
    keeps them; ``none`` never tries them; ``2,3`` fixes them in the model file, which validate
    and predict read back, while export (affine modes only) refuses with one line."""
    path = _duffing_csv(tmp_path / "duffing.csv", 1500, seed=0, noise=0.01)
    base = ["identify", str(path), "--input", "u", "--output", "y", "--na", "2", "--nb", "1", "--nk", "1"]
    assert main([*base, "--out", str(tmp_path / "auto.json")]) == 0
    choice = json.loads(capsys.readouterr().out)["choice"]
    assert choice["output_powers"]["tried"] and choice["output_powers"]["chosen"] == [2, 3]
    assert main([*base, "--output-powers", "none", "--out", str(tmp_path / "none.json")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert not summary["choice"]["output_powers"]["tried"] and "output_powers" not in summary
    assert main([*base, "--regions", "1", "--segmentation", "average", "--output-powers", "3,2",
                 "--out", str(tmp_path / "fixed.json")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["output_powers"] == [2, 3] and summary["train_fit_percent"] > 95
    stored = json.loads((tmp_path / "fixed.json").read_text())["structure"]
    assert stored["output_powers"] == [2, 3] and stored["regressor_names"][-1] == "((y(k-1)-c)/s)^3"
    assert main(["validate", str(tmp_path / "fixed.json"), str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fit_percent"] > 95
    assert main(["export", str(tmp_path / "fixed.json"), "--format", "json", "--out", str(tmp_path / "ss.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "needs affine modes" in err and "fixed.json" in err and len(err.splitlines()) == 1 and not (tmp_path / "ss.json").exists()


def test_identify_output_powers_name_a_partition_column_and_count_in_the_region_limit(tmp_path, capsys):
    """With ``--output-powers``, a power term is a valid ``--partition-column`` and its parameters
    count in ``--regions``' limit (a review found both left out)."""
    path = _duffing_csv(tmp_path / "d.csv", 800, seed=1)
    base = ["identify", str(path), "--input", "u", "--output", "y", "--na", "2", "--nb", "1", "--nk", "1",
            "--segmentation", "threshold"]
    assert main([*base, "--regions", "2", "--output-powers", "2", "--partition-column", "((y(k-1)-c)/s)^2",
                 "--out", str(tmp_path / "m.json")]) == 0
    assert json.loads(capsys.readouterr().out)["segmentation"] == "threshold"
    # (alternating: a threshold split has its own, tighter limit, 33 regions of 3 % of the rows)
    assert main([*base[:-1], "alternating", "--regions", "50", "--output-powers", "2,3",
                 "--out", str(tmp_path / "m50.json")]) == 2
    err = capsys.readouterr().err
    assert "--regions 50: expected at most 44 for 800 samples" in err and "6 parameters a region" in err


def test_data_without_a_time_column_is_taken_at_the_models_rate(tmp_path, capsys):
    """predict wrote the sample numbers as time_s (0, 1, 2 ... 'seconds') for a model sampled at
    10 ms; the samples of a file without time are taken at the model's rate."""
    import csv

    rng = np.random.default_rng(0)
    u = rng.uniform(-1, 1, 300)
    y = np.zeros(300)
    for k in range(1, 300):
        y[k] = 0.6 * y[k - 1] + u[k - 1]
    (tmp_path / "timed.csv").write_text("time_s,u,y\n" + "".join(f"{k * 0.01},{u[k]},{y[k]}\n" for k in range(300)))
    (tmp_path / "plain.csv").write_text("u,y\n" + "".join(f"{u[k]},{y[k]}\n" for k in range(300)))
    assert main(["identify", str(tmp_path / "timed.csv"), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                 "--segmentation", "average", "--out", str(tmp_path / "m.json")]) == 0
    assert main(["predict", str(tmp_path / "m.json"), str(tmp_path / "plain.csv"), "--out", str(tmp_path / "p.csv")]) == 0
    with open(tmp_path / "p.csv") as f:
        t = np.array([float(r["time_s"]) for r in csv.DictReader(f)])
    np.testing.assert_allclose(t, np.arange(300) * 0.01, atol=1e-12)


def test_a_time_column_in_milliseconds_and_a_rate_s_unit_are_read_by_their_names(tmp_path, capsys):
    """--time time_ms gave a sample time of 10 s for 10 ms steps; an output v_mm_s (mm/s) was
    labelled s."""
    d = make_system(5, rng=0, n=600)
    path = tmp_path / "ms.csv"
    write_csv(path, {"time_ms": np.arange(600) * 10.0, "u1": d.inputs[:, 0], "u2": d.inputs[:, 1],
                     "v_mm_s": d.output})
    assert main(["identify", str(path), "--input", "u1", "--input", "u2", "--output", "v_mm_s", "--na", "2",
                 "--nb", "2", "--segmentation", "average", "--time", "time_ms", "--out", str(tmp_path / "m.json")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["sample_time_s"] == pytest.approx(0.01)
    assert summary["units"]["v_mm_s"] == "mm/s"
    # a typed Parquet time stamp is in seconds already, whatever its name says (it was scaled twice)
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    ticks = 1_700_000_000_000_000 + np.arange(600) * 10_000
    pq.write_table(pa.table({"time_us": pa.array(ticks, pa.timestamp("us")), "u1": d.inputs[:, 0],
                             "u2": d.inputs[:, 1], "y": d.output}), tmp_path / "ts.parquet")
    assert main(["identify", str(tmp_path / "ts.parquet"), "--input", "u1", "--input", "u2", "--output", "y",
                 "--na", "2", "--nb", "2", "--segmentation", "average", "--time", "time_us",
                 "--out", str(tmp_path / "m2.json")]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] == pytest.approx(0.01)


def test_a_column_whose_name_says_another_unit_than_the_models_is_refused(tmp_path, capsys):
    """A model of pos_mm validated on pos_m (--output pos_m) scored -118055 % without a word on why."""
    d = make_system(5, rng=0, n=600)
    write_csv(tmp_path / "mm.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "pos_mm": 1000 * d.output})
    write_csv(tmp_path / "m.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "pos_m": d.output,
                                   "z_mm": 1000 * d.output})
    assert main(["identify", str(tmp_path / "mm.csv"), "--input", "u1", "--input", "u2", "--output", "pos_mm",
                 "--na", "2", "--nb", "2", "--segmentation", "average", "--out", str(tmp_path / "model.json")]) == 0
    capsys.readouterr()
    _expect_error(capsys, ["validate", str(tmp_path / "model.json"), str(tmp_path / "m.csv"), "--output", "pos_m"],
                  "--output 'pos_m': the model's 'pos_mm' is in mm, and this column's name says m")
    assert main(["validate", str(tmp_path / "model.json"), str(tmp_path / "m.csv"), "--output", "z_mm"]) == 0
    # a unit given as free text (--unit y=rpm) is not compared with a column's name (r/min)
    write_csv(tmp_path / "y.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output, "speed_rpm": d.output})
    assert main(["identify", str(tmp_path / "y.csv"), "--input", "u1", "--input", "u2", "--output", "y", "--unit", "y=rpm",
                 "--na", "2", "--nb", "2", "--segmentation", "average", "--out", str(tmp_path / "y.json")]) == 0
    assert main(["validate", str(tmp_path / "y.json"), str(tmp_path / "y.csv"), "--output", "speed_rpm"]) == 0
    # identify refuses what validate would: a known unit against the one the column's name says
    _expect_error(capsys, ["identify", str(tmp_path / "y.csv"), "--input", "u1", "--input", "u2", "--output",
                           "speed_rpm", "--unit", "speed_rpm=rad/s", "--na", "2", "--nb", "2", "--segmentation",
                           "average", "--out", str(tmp_path / "r.json")],
                  "--unit 'speed_rpm=rad/s': the column's name says its unit is 'r/min'")


def test_a_missing_cell_outside_the_selected_rows_does_not_matter(tmp_path, capsys):
    """A logger cut off on its last row: --rows that leave it out read the rest (a change of this
    session refused the whole file, in either CSV reader)."""
    d = make_system(5, rng=0, n=600)
    text = "u1,u2,y\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(d.inputs[:, 0], d.inputs[:, 1], d.output))
    for name, tail in (("cut.csv", "0.5,0.25,\n"), ("cut_trailing.csv", "0.5,0.25,,\n")):
        path = tmp_path / name
        path.write_text(text + tail if name == "cut.csv" else text.replace("\n", ",\n").replace("y,", "y", 1) + tail)
        assert main(["identify", str(path), *IDENTIFY, "--segmentation", "average", "--rows", "0:600",
                     "--out", str(tmp_path / "m.json")]) == 0, capsys.readouterr().err
        capsys.readouterr()
        _expect_error(capsys, ["identify", str(path), *IDENTIFY, "--segmentation", "average",
                               "--out", str(tmp_path / "m2.json")], "non-finite value")
        # inside a selection, the row is the file's (as --rows counts), not the selection's
        _expect_error(capsys, ["identify", str(path), *IDENTIFY, "--segmentation", "average", "--rows", "300:",
                               "--out", str(tmp_path / "m2.json")], "at row 600 (data rows count from 0")


@pytest.mark.parametrize("ts, said", [("0.01", "but it holds no numbers (text")])
def test_a_mat_sample_time_that_is_no_number_is_refused(tmp_path, capsys, ts, said):
    """A .mat Ts saved as text was passed over without a word (and with it the rate check), while
    Ts = 0 was refused. (A vector of that name is a signal's, 'dt', and is passed over.)"""
    path = tmp_path / "d.mat"
    rng = np.random.default_rng(0)
    savemat(path, {"u": rng.random(200), "y": rng.random(200), "Ts": ts})
    out = tmp_path / "m.json"
    _expect_error(capsys, ["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
                           "--out", str(out)], "the variable 'Ts' is taken as the sample time in seconds; expected", out)
    main(["identify", str(path), "--input", "u", "--output", "y", "--na", "1", "--nb", "1", "--out", str(out)])
    assert said in capsys.readouterr().err


def test_validate_counts_the_samples_beyond_the_training_range(tmp_path, data_csv, capsys):
    """Data inside the training ranges: no extrapolation line and shares 0; an input driven 1.5x
    beyond them: its share of samples outside, in the text and in --json, with the model's range."""
    model = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *IDENTIFY, "--segmentation", "average", "--out", str(model)]) == 0
    capsys.readouterr()
    assert main(["validate", str(model), str(data_csv)]) == 0
    assert "beyond the training range" not in capsys.readouterr().out
    assert main(["validate", str(model), str(data_csv), "--json"]) == 0
    inside = json.loads(capsys.readouterr().out)["beyond_training_range"]
    assert set(inside) == {"y", "u1", "u2"} and all(v["share"] == 0 for v in inside.values())
    d = make_system(5, rng=1, n=600)
    wide = tmp_path / "wide.csv"
    write_csv(wide, {"time_s": np.arange(600) * 0.01, "u1": 1.5 * d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    assert main(["validate", str(model), str(wide), "--json"]) == 0
    beyond = json.loads(capsys.readouterr().out)["beyond_training_range"]
    lo, hi = beyond["u1"]["training_range"]
    u1 = 1.5 * d.inputs[2:, 0]  # after the model's 2 initial conditions
    assert beyond["u1"]["share"] == pytest.approx(np.mean((u1 < lo) | (u1 > hi)), abs=1e-6) and beyond["u1"]["share"] > 0.1
    assert main(["validate", str(model), str(wide)]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert line.startswith("beyond the training range: ") and line.endswith("the model extrapolates there")
    assert f"'u1' {100 * beyond['u1']['share']:.2g} % (identified on {lo:.4g} to {hi:.4g})" in line
    # predict says it too, after the line of what it wrote (on stderr when the table goes to stdout)
    assert main(["predict", str(model), str(wide), "--out", str(tmp_path / "p.csv")]) == 0
    said = capsys.readouterr().out.strip().splitlines()
    assert said[0].startswith("wrote ") and said[1] == line
    assert main(["predict", str(model), str(data_csv), "--out", str(tmp_path / "q.csv")]) == 0
    assert "beyond" not in capsys.readouterr().out
    # and residuals, whose tests say as little where the model extrapolates
    assert main(["residuals", str(model), str(wide)]) == 0
    assert capsys.readouterr().out.strip().splitlines()[-1] == line
    assert main(["residuals", str(model), str(wide), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["beyond_training_range"] == beyond
    assert main(["residuals", str(model), str(data_csv)]) == 0
    assert "beyond" not in capsys.readouterr().out


def test_identify_with_hinging_on_the_tank_and_its_partition_column(tmp_path, capsys):
    """`--segmentation hinging`: the tank that empties and overflows, its hinges the two
    saturations; the model file validates; `--partition-column u(k-1)` (refused before with a
    method that returns its partition) leaves the hinges on that column only."""
    rng = np.random.default_rng(0)
    n = 2000
    u = np.repeat(rng.uniform(-1.2, 1.2, n // 30 + 1), 30)[:n]
    y = np.zeros(n)
    for k in range(1, n):
        y[k] = min(10.0, max(0.0, y[k - 1] + 0.2 * u[k - 1]))
    data = tmp_path / "tank.csv"
    write_csv(data, {"time_s": np.arange(n) * 0.1, "u": u, "y": y + 0.05 * rng.standard_normal(n)})
    out = tmp_path / "t.json"
    args = ["identify", str(data), "--input", "u", "--output", "y", "--na", "1", "--nb", "1",
            "--segmentation", "hinging", "--regions", "3"]
    assert main([*args, "--out", str(out)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["segmentation"] == "hinging" and summary["n_regions"] == 3
    assert summary["train_fit_percent"] > 90
    assert main(["validate", str(out), str(data), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fit_percent"] == pytest.approx(summary["train_fit_percent"], abs=0.01)
    assert main([*args, "--partition-column", "u", "--out", str(out)]) == 0
    capsys.readouterr()
    polyhedra = json.loads(out.read_text())["partition"]["polyhedra"]
    # regressor columns y(k-1), u(k-1): every boundary's weight on y(k-1) is zero
    assert all(row[0] == 0 for p in polyhedra for row in p["H"])
    assert any(row[1] != 0 for p in polyhedra for row in p["H"])


def test_a_share_beyond_the_training_range_reads_as_a_percentage():
    """All of a record beyond the training range read "'y' 1e+02 %" (two significant digits)."""
    from hwpts.commands.model import _beyond_line

    line = _beyond_line({"y": {"share": 1.0, "training_range": [0.0, 1.0]},
                         "u": {"share": 0.0037, "training_range": [-1.0, 1.0]}})
    assert "'y' 100 % (identified on 0 to 1)" in line and "'u' 0.37 %" in line
