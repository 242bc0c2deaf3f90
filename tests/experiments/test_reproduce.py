"""End to end: ``hwpts reproduce --quick`` against the contract of DESIGN.md section 4."""

import json
import re

import numpy as np
import pytest

from hwpts.cli import main
from hwpts.io.datasets import read_csv
from hwpts.io.models import load_model

CASES = ("case1", "case2", "case3", "case4")
FIGURES = ("fig03_sweeps.png", "fig04_hysteresis_gap.png", "fig05_averaged_surface.png", "fig06_submodels.png",
           "fig07_fracture_line.png", "fig08_case1.png", "fig09_case2.png", "fig10_case3.png", "fig11_case4.png")


def test_summary_follows_the_contract(quick_run):
    s = json.loads((quick_run / "summary.json").read_text())
    assert s["schema"] == "hwpts.reproduce/1"
    assert s["seed"] == 0 and s["quick"] is True
    ss = s["steady_state"]
    assert ss["points_per_sweep"] == 2187
    assert 20 < ss["max_hysteresis_gap_percent"] < 40
    assert len(ss["calibration"]) == 4
    for c in ss["calibration"]:
        assert set(c) == {"valve_voltage_v", "pump_speed_rpm", "paper_rpm", "model_rpm"}
        assert c["model_rpm"] == pytest.approx(c["paper_rpm"], rel=0.03)
    for name in ("average", "zscore", "kmeans", "paper", "best"):
        m = s["methods"][name]
        assert isinstance(m["n_regions"], int)
        for case in CASES:
            fit = m["cases"][case]["fit_percent"]
            assert fit is None or isinstance(fit, float)
    assert s["methods"]["average"]["n_regions"] == 1
    assert s["methods"]["paper"]["n_regions"] == 3
    assert s["paper_reported_fit_percent"] == {"case2": 92, "case3": 93, "case4": 91}
    assert s["timings_s"]["total"] > 0
    for stage in ("sweeps", "segmentation", "recording", "identification", "validation", "figures_and_report"):
        assert stage in s["timings_s"]
    from hwpts import __version__

    run = s["run"]
    assert run["hwpts_version"] == __version__ and run["seed"] == 0
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", run["created_utc"])
    assert run["command"].startswith("hwpts reproduce --quick")


def test_quick_run_already_lands_near_the_paper(quick_run):
    # the full run is checked in the benchmark; the quick one must already be in the neighbourhood
    s = json.loads((quick_run / "summary.json").read_text())
    for case in ("case2", "case3", "case4"):
        assert s["methods"]["paper"]["cases"][case]["fit_percent"] >= 85
    for case in CASES:
        assert s["methods"]["best"]["cases"][case]["fit_percent"] >= 90
        assert s["methods"]["best"]["cases"][case]["fit_percent"] > s["methods"]["average"]["cases"][case]["fit_percent"]
    r = s["steady_state"]["hysteresis_half_width_v"]
    assert r == pytest.approx(0.25, abs=0.01)  # the test bed's play, read off the sweeps


def test_every_output_file(quick_run):
    for name in FIGURES:
        data = (quick_run / "figures" / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000, name
    lines = (quick_run / "data" / "steady_state_sweeps.csv").read_text().splitlines()
    assert lines[0] == "valve_voltage_v,pump_speed_rpm,direction,motor_a_speed_rpm"
    directions = [line.split(",")[2] for line in lines[1:]]
    assert {d: directions.count(d) for d in set(directions)} == {"up": 2187, "down": 2187, "average": 2187}
    for case in CASES:
        cols = read_csv(quick_run / "data" / f"{case}.csv")
        for col in ("time_s", "valve_voltage_v", "valve_voltage_play_v", "pump_speed_rpm", "motor_a_speed_rpm",
                    "simulated_paper_rpm", "simulated_best_rpm"):
            assert col in cols, (case, col)
    for name in ("average", "zscore", "kmeans", "paper", "best"):
        model = load_model(quick_run / "models" / f"{name}.json")
        assert model.n_regions_ >= 1
    html = (quick_run / "report.html").read_text()
    assert html.count("data:image/png;base64,") == len(FIGURES)
    assert "id='fit-table'" in html and "http://" not in html and "https://" not in html
    assert not [p for p in quick_run.parent.iterdir() if p.name.startswith(".results.")]  # no staging left


def test_saved_model_validates_on_saved_case(quick_run, capsys):
    status = main(["validate", str(quick_run / "models" / "paper.json"), str(quick_run / "data" / "case3.csv"), "--json"])
    out = json.loads(capsys.readouterr().out)
    s = json.loads((quick_run / "summary.json").read_text())
    assert status == 0
    assert out["fit_percent"] == pytest.approx(s["methods"]["paper"]["cases"]["case3"]["fit_percent"], abs=0.05)


def test_same_seed_same_numbers(quick_run, tmp_path):
    other = tmp_path / "again"
    assert main(["reproduce", "--quick", "--out", str(other), "--seed", "0"]) == 0
    a = json.loads((quick_run / "summary.json").read_text())
    b = json.loads((other / "summary.json").read_text())
    assert a["run"]["seed"] == b["run"]["seed"] == 0 and a["run"]["hwpts_version"]
    for s in (a, b):
        s.pop("timings_s")
        s.pop("run")  # the date differs
        for m in s["methods"].values():
            m.pop("fit_time_s")
    assert a == b


def test_refuses_a_foreign_folder(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    status = main(["reproduce", "--quick", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "not an earlier hwpts run" in err[0]
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]


def test_failed_stage_keeps_the_earlier_run(tmp_path, capsys, monkeypatch):
    from hwpts.errors import IdentificationError
    from hwpts.experiments import paper

    out = tmp_path / "results"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"schema": "hwpts.reproduce/1", "seed": 7}))
    (out / "stale.txt").write_text("from an earlier run")
    (out / ".hwpts-files").write_text(json.dumps(["summary.json", "stale.txt"]))

    def broken(_sweeps):
        raise IdentificationError("no fracture found (test)")

    monkeypatch.setattr(paper, "find_fracture", broken)
    status = main(["reproduce", "--quick", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1
    assert "stage 'segmentation' failed" in err[0] and "Traceback" not in err[0]
    assert sorted(p.name for p in out.iterdir()) == [".hwpts-files", "stale.txt", "summary.json"]
    assert json.loads((out / "summary.json").read_text())["seed"] == 7
    assert [p.name for p in tmp_path.iterdir()] == ["results"]  # the staging folder is gone


def test_a_new_run_replaces_an_earlier_one_as_a_whole(quick_run, tmp_path):
    import shutil

    out = tmp_path / "results"
    shutil.copytree(quick_run, out)
    (out / "figures" / "fig99_from_an_older_version.png").write_bytes(b"old")
    written = json.loads((out / ".hwpts-files").read_text())  # the earlier run wrote that figure
    (out / ".hwpts-files").write_text(json.dumps([*written, "figures/fig99_from_an_older_version.png"]))
    assert main(["reproduce", "--quick", "--out", str(out), "--seed", "1"]) == 0
    assert not (out / "figures" / "fig99_from_an_older_version.png").exists()
    assert json.loads((out / "summary.json").read_text())["seed"] == 1
    assert np.all([p.name != "fig99_from_an_older_version.png" for p in (out / "figures").iterdir()])


def test_a_file_the_earlier_run_did_not_write_is_not_deleted(quick_run, tmp_path, capsys):
    """A run replaces its folder as a whole: the user's own notes in an earlier run's folder were
    deleted with it; now the run is refused and nothing is touched."""
    import shutil

    out = tmp_path / "results"
    shutil.copytree(quick_run, out)
    (out / "notes.txt").write_text("mine")
    capsys.readouterr()
    assert main(["reproduce", "--quick", "--out", str(out)]) == 2
    assert "also holds files it did not write (notes.txt)" in capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "mine"
    # a copy made with `cp -r run/* copy/` leaves the hidden list of files behind: nothing tells the
    # run's files from the user's, and the notes were deleted with the folder
    (out / ".hwpts-files").unlink()
    assert main(["reproduce", "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "an earlier run's folder without its list of files (.hwpts-files)" in err[0]
    assert (out / "notes.txt").read_text() == "mine"


def test_the_models_know_their_signals_units(quick_run, tmp_path, capsys):
    """The models of `reproduce` carried no units, so their guard against a column in other units
    (what `identify`'s models refuse) never ran: a speed in rad/s scored -1389 % without a reason."""
    import csv

    for path in sorted((quick_run / "models").glob("*.json")):
        units = json.loads(path.read_text())["signals"]["units"]
        assert units["motor_a_speed_rpm"] == "r/min" and units["pump_speed_rpm"] == "r/min", path.name
    with open(quick_run / "data" / "case2.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    data = tmp_path / "rad.csv"
    with open(data, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=[*rows[0], "motor_a_speed_rad_s"])
        writer.writeheader()
        for row in rows:
            writer.writerow({**row, "motor_a_speed_rad_s": float(row["motor_a_speed_rpm"]) * np.pi / 30})
    capsys.readouterr()
    assert main(["validate", str(quick_run / "models" / "best.json"), str(data), "--input", "valve_voltage_play_v",
                 "--input", "pump_speed_rpm", "--output", "motor_a_speed_rad_s"]) == 2
    assert "is in r/min, and this column's name says rad/s" in capsys.readouterr().err
