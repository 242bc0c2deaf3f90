"""``hwpts validate --plot``, ``residuals``, ``predict --horizon``, ``export`` and the sample time
kept in the model (issues 10 and 12)."""

import json
import runpy

import numpy as np
import pytest

from hwpts.cli import main
from hwpts.io.datasets import write_csv
from hwpts.io.models import load_model


def _second_order(seed=0, n=3000, dt=0.01):
    """Two modes switching on u1(k-1), second-order dynamics, white equation noise (ARX structure)."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, (n, 2))
    y = np.zeros(n)
    e = 0.05 * rng.standard_normal(n)
    for k in range(2, n):
        if u[k - 1, 0] >= 0:
            y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + u[k - 1, 0] + 0.3 * u[k - 1, 1] + 0.1 + e[k]
        else:
            y[k] = 1.2 * y[k - 1] - 0.5 * y[k - 2] - 0.5 * u[k - 1, 0] + 0.8 * u[k - 1, 1] - 0.1 + e[k]
    return np.arange(n) * dt, u, y


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("analysis")
    t, u, y = _second_order()
    write_csv(d / "data.csv", {"time_s": t, "valve_v": u[:, 0], "u2": u[:, 1], "y_mm": y})
    common = ["--input", "valve_v", "--input", "u2", "--output", "y_mm", "--nb", "1",
              "--segmentation", "hyperplane", "--hyperplane", "1,0@valve_v(k-1)"]
    assert main(["identify", str(d / "data.csv"), *common, "--na", "2", "--out", str(d / "good.json")]) == 0
    assert main(["identify", str(d / "data.csv"), *common, "--na", "1", "--out", str(d / "wrong.json")]) == 0
    return d


def _png_ok(path, min_size=(400, 300)):
    import matplotlib.image as mpimg

    img = mpimg.imread(path)
    assert img.shape[1] >= min_size[0] and img.shape[0] >= min_size[1]
    assert float(np.std(img[..., :3])) > 0.05  # not blank


def test_validate_plot_writes_a_figure(files, capsys):
    out = files / "v.png"
    assert main(["validate", str(files / "good.json"), str(files / "data.csv"), "--plot", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    _png_ok(out)


def test_a_name_the_figure_font_cannot_draw_is_one_warning_line(files, tmp_path, capsys):
    """A data file named in Chinese: matplotlib warned once per character its font lacks (four
    'hwpts: warning: Glyph 27169 (...) missing from font(s) DejaVu Sans.' lines for 模型); one line
    now, naming the characters, or none where a font that draws them is installed (it is used)."""
    from matplotlib import font_manager

    from hwpts.reporting.figures import FALLBACK_FONTS

    named = tmp_path / "记录.csv"
    named.write_bytes((files / "data.csv").read_bytes())
    assert main(["validate", str(files / "good.json"), str(named), "--plot", str(tmp_path / "图.png")]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("hwpts: warning")]
    if {f.name for f in font_manager.fontManager.ttflist} & set(FALLBACK_FONTS):
        assert lines == []
    else:
        assert len(lines) == 1 and "cannot draw '记录'" in lines[0] and "Noto Sans CJK" in lines[0], lines
    _png_ok(tmp_path / "图.png")


def test_fallback_fonts_go_behind_the_families_in_use():
    from hwpts.reporting.figures import fallback_families

    assert fallback_families(["sans-serif"], {"DejaVu Sans"}) == ["sans-serif"]
    assert fallback_families("serif", {"SimHei", "Noto Sans CJK JP"}) == ["serif", "Noto Sans CJK JP", "SimHei"]
    assert fallback_families(["SimHei"], {"SimHei"}) == ["SimHei"]


def test_validate_plot_labels_the_axis_by_the_datas_time(files, tmp_path, monkeypatch, capsys):
    """A model without a sample time validated on data with a time column: the axis is in seconds
    (it was labelled "sample" under the data's seconds); on data without one, it is the sample."""
    import hwpts.reporting.analysis as figures

    seen = []
    real = figures.validation_figure
    monkeypatch.setattr(figures, "validation_figure", lambda *a, **k: seen.append(k["time_unit"]) or real(*a, **k))
    t, u, y = _second_order(n=400)
    write_csv(tmp_path / "notime.csv", {"valve_v": u[:, 0], "u2": u[:, 1], "y_mm": y})
    fit = ["--input", "valve_v", "--input", "u2", "--output", "y_mm", "--na", "2", "--nb", "1", "--segmentation", "average"]
    assert main(["identify", str(tmp_path / "notime.csv"), *fit, "--out", str(tmp_path / "m.json")]) == 0
    assert main(["validate", str(tmp_path / "m.json"), str(files / "data.csv"), "--plot", str(tmp_path / "a.png")]) == 0
    assert main(["validate", str(tmp_path / "m.json"), str(tmp_path / "notime.csv"), "--plot", str(tmp_path / "b.png")]) == 0
    assert seen == ["s", None]
    capsys.readouterr()


def test_residuals_tell_a_correct_model_from_a_wrong_one(files, capsys):
    capsys.readouterr()
    assert main(["residuals", str(files / "good.json"), str(files / "data.csv"), "--json",
                 "--plot", str(files / "r.png")]) == 0
    good = json.loads(capsys.readouterr().out)
    assert main(["residuals", str(files / "wrong.json"), str(files / "data.csv"), "--json"]) == 0
    wrong = json.loads(capsys.readouterr().out)
    assert good["outside_share"]["all"] < 0.05 and good["white"]
    assert wrong["outside_share"]["all"] > 0.20 and not wrong["white"]
    assert good["lags"] == 25 and len(good["autocorrelation"]) == 26
    assert set(good["cross_correlation"]) == {"valve_v", "u2"}
    _png_ok(files / "r.png")


def test_residuals_of_a_constant_input_are_not_tested(files, tmp_path, capsys):
    """An input held constant (the pump speed through a valve test) has no correlation with the
    residuals to test: said, and null in the JSON (it was "uncorrelated", every lag inside the band)."""
    t, u, y = _second_order(seed=1, n=600)
    held = tmp_path / "held.csv"
    write_csv(held, {"time_s": t, "valve_v": u[:, 0], "u2": np.full_like(t, 0.3), "y_mm": y})
    capsys.readouterr()
    assert main(["residuals", str(files / "good.json"), str(held), "--plot", str(tmp_path / "r.png")]) == 0
    out = capsys.readouterr().out
    assert "input u2: constant on these data: not tested" in out and "input valve_v:" in out
    assert main(["residuals", str(files / "good.json"), str(held), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["outside_share"]["cross_correlation"]["u2"] is None
    assert result["independent_of_inputs"] is None and result["untested_inputs"] == ["u2"]
    # a tested input that is correlated says so whatever the untested one (it was null)
    assert main(["residuals", str(files / "wrong.json"), str(held), "--json"]) == 0
    wrong = json.loads(capsys.readouterr().out)
    assert wrong["outside_share"]["cross_correlation"]["valve_v"] > 0.05 and wrong["independent_of_inputs"] is False
    assert result["white"] is not None


def test_predict_horizon_one_is_one_step_and_n_is_the_free_run(files, tmp_path):
    data, model = str(files / "data.csv"), str(files / "good.json")

    def predicted(*extra):
        out = tmp_path / "p.csv"
        assert main(["predict", model, data, "--out", str(out), *extra]) == 0
        return np.genfromtxt(out, delimiter=",", names=True)["y_mm_predicted"]

    np.testing.assert_array_equal(predicted("--horizon", "1"), predicted("--mode", "one-step"))
    np.testing.assert_array_equal(predicted("--horizon", "3000"), predicted("--mode", "simulate"))
    five = predicted("--horizon", "5")
    assert not np.array_equal(five, predicted("--horizon", "1"))


def test_predict_refuses_horizon_with_mode(files, tmp_path, capsys):
    out = tmp_path / "p.csv"
    assert main(["predict", str(files / "good.json"), str(files / "data.csv"), "--out", str(out),
                 "--horizon", "4", "--mode", "one-step"]) == 2
    assert "--horizon" in capsys.readouterr().err and not out.exists()


def test_a_model_refuses_data_at_another_sample_time(files, tmp_path, capsys):
    model = load_model(files / "good.json")
    assert model.sample_time_ == pytest.approx(0.01) and model.units_ == {"valve_v": "V", "y_mm": "mm"}
    t, u, y = _second_order()
    fast = tmp_path / "fast.csv"
    write_csv(fast, {"time_s": t / 10, "valve_v": u[:, 0], "u2": u[:, 1], "y_mm": y})
    capsys.readouterr()
    assert main(["validate", str(files / "good.json"), str(fast)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sample time 0.001 s (1000 Hz) differs from the model's 0.01 s (100 Hz)" in err[0]
    assert main(["validate", str(files / "good.json"), str(fast), "--resample", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_samples"] == 300


def _ten_ms_model(tmp_path, capsys, n):
    """Data of ``n`` samples at 10 ms and a model identified on them: (t, u, y, model path, fit options)."""
    t, u, y = _second_order(n=n)
    model = tmp_path / "m.json"
    write_csv(tmp_path / "slow.csv", {"time_s": t, "u1": u[:, 0], "u2": u[:, 1], "y": y})
    fit = ["--input", "u1", "--input", "u2", "--output", "y", "--na", "2", "--nb", "1", "--segmentation", "average"]
    assert main(["identify", str(tmp_path / "slow.csv"), *fit, "--out", str(model)]) == 0
    capsys.readouterr()
    return t, u, y, model, fit


@pytest.mark.parametrize("form", ["parquet unnamed index", "parquet timestamp", "csv iso", "csv iso zone"])
def test_time_stamps_are_the_time_axis_by_their_type_or_text(tmp_path, capsys, form):
    """A Parquet column typed as time stamps (pandas' DatetimeIndex written as it is, or named
    ``timestamp``) and a CSV time column of ISO 8601 date-times are the time axis: 5 ms data were
    validated against a 10 ms model at exit 0, and the model fitted on them had no sample time."""
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    t, u, y, model, fit = _ten_ms_model(tmp_path, capsys, 1000)
    stamps = np.datetime64("2024-01-01T00:00:00", "ns") + (t * 5e8).astype("timedelta64[ns]")  # every 5 ms
    if form.startswith("parquet"):
        fast = tmp_path / "fast.parquet"
        name = "__index_level_0__" if form.endswith("index") else "timestamp"
        pq.write_table(pa.table({"u1": u[:, 0], "u2": u[:, 1], "y": y, name: pa.array(stamps)}), fast)
    else:
        zone = "Z" if form.endswith("zone") else ""
        text = [str(s).replace("T", " " if not zone else "T") + zone for s in stamps]
        fast = tmp_path / "fast.csv"
        fast.write_text("time,u1,u2,y\n" + "".join(f"{s},{float(a)!r},{float(b)!r},{float(c)!r}\n" for s, a, b, c in
                                                    zip(text, u[:, 0], u[:, 1], y)))
    assert main(["validate", str(model), str(fast)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sample time 0.005 s (200 Hz) differs from the model's 0.01 s (100 Hz)" in err[0]
    assert main(["identify", str(fast), *fit, "--out", str(tmp_path / "fast.json")]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] == pytest.approx(0.005)


def test_time_stamps_not_taken_as_the_time_axis_are_said(tmp_path, capsys):
    """ISO date-times in a column of another name, or that do not all read (an empty cell), leave the
    rate unchecked: a warning says so (it was silent); --time on such a column is refused in a line;
    a decimal comma (ISO 8601 allows it) reads."""
    t, u, y, model, fit = _ten_ms_model(tmp_path, capsys, 400)
    stamps = [str(np.datetime64("2024-01-01T00:00:00", "ms") + np.timedelta64(5 * k, "ms")).replace("T", " ")
              for k in range(t.size)]

    def write(name, column, cells, sep=","):
        rows = "".join(sep.join([c, repr(float(a)), repr(float(b)), repr(float(d))]) + "\n"
                       for c, a, b, d in zip(cells, u[:, 0], u[:, 1], y))
        (tmp_path / name).write_text(sep.join([column, "u1", "u2", "y"]) + "\n" + rows)
        return str(tmp_path / name)

    named = write("named.csv", "timestamp", stamps)
    assert main(["validate", str(model), named]) == 0
    err = capsys.readouterr().err
    assert "hwpts: warning:" in err and "'timestamp' holds time stamps but no time axis was taken" in err
    assert main(["validate", str(model), named, "--time", "timestamp"]) == 2
    assert "sample time 0.005 s (200 Hz) differs" in capsys.readouterr().err
    empty = write("empty.csv", "time", [s if k != 9 else "" for k, s in enumerate(stamps)])
    assert main(["validate", str(model), empty]) == 0 and "'time' holds time stamps" in capsys.readouterr().err
    assert main(["validate", str(model), empty, "--time", "time"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("hwpts: error: --time time: expected ISO 8601 date-times in every row")
    comma = write("comma.csv", "time", [s.replace(".", ",") for s in stamps], sep=";")
    assert main(["validate", str(model), comma]) == 2
    assert "sample time 0.005 s (200 Hz) differs" in capsys.readouterr().err


def test_a_time_column_is_found_by_its_conventional_name(tmp_path, capsys):
    """A model fitted on data whose time column is named t_s (as the pick-and-place files) knows its
    sample time without --time, and data at another rate in a column named t are refused (before,
    only time_s was looked for: a 400 Hz model gave a fit on 4 kHz data with exit 0)."""
    t, u, y = _second_order(n=1000)
    slow = tmp_path / "slow.csv"
    write_csv(slow, {"t_s": t, "u1": u[:, 0], "u2": u[:, 1], "y": y})
    model = tmp_path / "m.json"
    fit = ["--input", "u1", "--input", "u2", "--output", "y", "--na", "2", "--nb", "1", "--segmentation", "average"]
    assert main(["identify", str(slow), *fit, "--out", str(model)]) == 0
    assert json.loads(capsys.readouterr().out)["sample_time_s"] == pytest.approx(0.01)
    fast = tmp_path / "fast.csv"
    write_csv(fast, {"t": t / 10, "u1": u[:, 0], "u2": u[:, 1], "y": y})
    assert main(["validate", str(model), str(fast), "--json"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sample time 0.001 s (1000 Hz) differs from the model's 0.01 s (100 Hz)" in err[0]
    assert "('t' is taken as the time column by its name; --time none uses the sample index)" in err[0]
    assert main(["validate", str(model), str(fast), "--time", "none", "--json"]) == 0  # the user says so
    assert json.loads(capsys.readouterr().out)["n_samples"] == 1000
    # a column named like time that holds text is no time axis; one that is not increasing is named
    text = tmp_path / "text.csv"
    text.write_text("time,u1,u2,y\n" + "".join(f"day {k},{a},{b},{c}\n" for k, (a, b, c) in
                                                enumerate(zip(u[:, 0], u[:, 1], y))))
    assert main(["validate", str(model), str(text), "--json"]) == 0
    capsys.readouterr()
    shuffled = tmp_path / "shuffled.csv"
    write_csv(shuffled, {"t": t[::-1], "u1": u[:, 0], "u2": u[:, 1], "y": y})
    assert main(["validate", str(model), str(shuffled)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'t' is taken as the time column by its name; --time none uses the sample index" in err[0]
    # a column named by --time is the time axis: one that does not increase was dropped without a
    # word (and with it the rate check: data at another rate validated at exit 0)
    odd = tmp_path / "odd.csv"
    write_csv(odd, {"t": t / 10, "u1": u[:, 0], "u2": u[:, 1], "y": y, "temp": np.cos(t)})
    assert main(["validate", str(model), str(odd), "--time", "temp"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the time column 'temp' must be strictly increasing; it is not at row" in err[0]


def test_columns_are_matched_by_name_and_can_be_mapped(files, tmp_path, capsys):
    t, u, y = _second_order()
    shuffled = tmp_path / "shuffled.csv"
    write_csv(shuffled, {"y_mm": y, "u2": u[:, 1], "time_s": t, "valve_v": u[:, 0]})
    renamed = tmp_path / "renamed.csv"
    write_csv(renamed, {"time_s": t, "a": u[:, 0], "b": u[:, 1], "out": y})
    results = []
    for path, extra in ((files / "data.csv", []), (shuffled, []),
                        (renamed, ["--input", "a", "--input", "b", "--output", "out"])):
        assert main(["validate", str(files / "good.json"), str(path), "--json", *extra]) == 0
        results.append(json.loads(capsys.readouterr().out)["fit_percent"])
    assert results[0] == results[1] == results[2]
    assert main(["validate", str(files / "good.json"), str(renamed), "--input", "a"]) == 2
    assert "--input was given 1 time(s); the model has 2 inputs" in capsys.readouterr().err


def test_export_control_matlab_json(files, tmp_path, capsys):
    control = pytest.importorskip("control")
    from scipy.io import loadmat

    model = load_model(files / "good.json")
    reference = model.to_control()
    py = tmp_path / "modes.py"
    assert main(["export", str(files / "good.json"), "--format", "control", "--out", str(py)]) == 0
    ns = runpy.run_path(str(py))
    assert len(ns["MODES"]) == len(reference) == 2
    for got, ref in zip(ns["MODES"], reference):
        for a, b in ((got.A, ref.A), (got.B, ref.B), (got.C, ref.C), (got.D, ref.D)):
            np.testing.assert_array_equal(a, b)
        assert got.dt == ref.dt == pytest.approx(0.01)
        assert isinstance(got, control.StateSpace)
    mat = tmp_path / "m.mat"
    assert main(["export", str(files / "good.json"), "--format", "matlab", "--out", str(mat)]) == 0
    m = loadmat(mat)
    assert m["A"].shape == (4, 4, 2) and m["B"].shape == (4, 2, 2) and m["c"].shape == (1, 2)
    np.testing.assert_allclose(m["A"][:, :, 1], reference[1].A)
    np.testing.assert_allclose(np.column_stack([m["B"][:, :, 0], m["e"][:, :, 0]]), reference[0].B)
    assert float(m["Ts"].ravel()[0]) == pytest.approx(0.01) and m["H"].shape == (2, 1)
    # the same model, the same file: scipy writes the time into the header's text, which hwpts replaces
    again = tmp_path / "again.mat"
    assert main(["export", str(files / "good.json"), "--format", "matlab", "--out", str(again)]) == 0
    assert again.read_bytes() == mat.read_bytes()
    assert loadmat(again)["__header__"].startswith(b"MATLAB 5.0 MAT-file, written by hwpts")
    js = tmp_path / "m.json"
    assert main(["export", str(files / "good.json"), "--format", "json", "--out", str(js)]) == 0
    doc = json.loads(js.read_text())
    assert doc["schema"] == "hwpts.statespace/1" and len(doc["modes"]) == 2
    np.testing.assert_allclose(doc["modes"][0]["A"], reference[0].A)
    capsys.readouterr()
    assert main(["export", str(files / "good.json"), "--format", "matlab", "--out", str(tmp_path / "x.json")]) == 2
    assert "writes a .mat file" in capsys.readouterr().err


def test_a_model_file_without_the_signals_section_still_loads(files, tmp_path):
    from hwpts.io.models import REQUIRED_SECTIONS, checksum

    doc = json.loads((files / "good.json").read_text())
    del doc["signals"]
    doc["checksum"] = {"algorithm": "sha256", "sections": list(REQUIRED_SECTIONS),
                       "value": checksum(doc, REQUIRED_SECTIONS)}
    old = tmp_path / "old.json"
    old.write_text(json.dumps(doc))
    model = load_model(old)
    assert model.sample_time_ is None and model.units_ == {}


def test_resample_takes_a_jittered_time_axis(files, tmp_path, capsys):
    """--resample refused a time column with jitter ('not uniformly sampled ... resample the data')
    although resampling is what it does: it interpolates it onto the model's grid; without it the
    message names --resample."""
    t, u, y = _second_order()
    jittered = t + np.random.default_rng(1).uniform(-0.002, 0.002, t.size) * (np.arange(t.size) > 0)
    path = tmp_path / "jit.csv"
    write_csv(path, {"time_s": jittered, "valve_v": u[:, 0], "u2": u[:, 1], "y_mm": y})
    assert main(["validate", str(files / "good.json"), str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not uniformly sampled" in err[0] and "or pass --resample to interpolate it" in err[0]
    assert main(["validate", str(files / "good.json"), str(path), "--resample", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["n_samples"] >= 2999 and result["fit_percent"] > 50  # (its end is jittered)


def test_resample_refuses_to_bridge_a_gap(files, tmp_path, capsys):
    """--resample filled a gap of 25 samples with a straight line, without a word."""
    t, u, y = _second_order()
    path = tmp_path / "gap.csv"
    write_csv(path, {"time_s": t + 0.25 * (np.arange(t.size) >= 1500), "valve_v": u[:, 0], "u2": u[:, 1], "y_mm": y})
    assert main(["validate", str(files / "good.json"), str(path), "--resample"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--resample: the time column has a gap of 0.26 s at row 1500" in err[0]
