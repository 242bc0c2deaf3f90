import json

import numpy as np
import pytest

from hwpts.cli import main
from hwpts.io.datasets import read_csv


def run(argv, capsys):
    status = main(argv)
    out, err = capsys.readouterr()
    return status, out, err


def assert_one_line_error(status, err, *fragments):
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_steady_state_prints_the_contract_keys(capsys):
    status, out, _ = run(["plant", "steady-state", "--valve-voltage", "1.8", "--pump-speed", "904"], capsys)
    assert status == 0
    obj = json.loads(out)
    assert set(obj) == {
        "valve_voltage_v", "pump_speed_rpm", "motor_a_speed_rpm", "motor_b_speed_rpm",
        "pump_pressure_pa", "motor_a_pressure_pa", "motor_b_pressure_pa",
    }
    assert obj["motor_a_speed_rpm"] == pytest.approx(1566, rel=0.03)


def test_steady_state_branches(capsys):
    speeds = {}
    for branch in ("up", "none", "down"):
        _, out, _ = run(["plant", "steady-state", "--valve-voltage", "2.6", "--pump-speed", "700", "--branch", branch], capsys)
        speeds[branch] = json.loads(out)["motor_a_speed_rpm"]
    assert speeds["up"] > speeds["none"] > speeds["down"]


@pytest.mark.parametrize(
    "argv, fragments",
    [
        (["--valve-voltage", "nan", "--pump-speed", "500"], ["--valve-voltage", "finite", "'nan'"]),
        (["--valve-voltage", "abc", "--pump-speed", "500"], ["--valve-voltage", "expected a number", "'abc'"]),
        (["--valve-voltage", "2", "--pump-speed", "-100"], ["--pump-speed", ">= 0", "'-100'"]),
        (["--valve-voltage", "2", "--pump-speed", "inf"], ["--pump-speed", "finite"]),
        (["--valve-voltage", "2"], ["--pump-speed", "required"]),
        (["--valve-voltage", "2", "--pump-speed", "500", "--branch", "left"], ["--branch", "left"]),
    ],
)
def test_steady_state_bad_arguments(argv, fragments, capsys):
    status, out, err = run(["plant", "steady-state", *argv], capsys)
    assert out == ""
    assert_one_line_error(status, err, *fragments)


def test_sweep_writes_up_down_average(tmp_path, capsys):
    out_file = tmp_path / "sweep.csv"
    status, out, _ = run(["plant", "sweep", "--out", str(out_file), "--voltages", "1.2:3.8:5", "--pump-speeds", "200:1000:4"], capsys)
    assert status == 0 and "20 points per sweep" in out
    text = out_file.read_text().splitlines()
    assert text[0] == "valve_voltage_v,pump_speed_rpm,direction,motor_a_speed_rpm"
    directions = [line.split(",")[2] for line in text[1:]]
    assert directions.count("up") == directions.count("down") == directions.count("average") == 20
    rows = [line.split(",") for line in text[1:]]
    up = np.array([float(r[3]) for r in rows if r[2] == "up"])
    down = np.array([float(r[3]) for r in rows if r[2] == "down"])
    avg = np.array([float(r[3]) for r in rows if r[2] == "average"])
    assert np.allclose(avg, (up + down) / 2, rtol=1e-8)


@pytest.mark.parametrize(
    "grid_args, fragments",
    [
        (["--voltages", "3.8:1.2:27"], ["--voltages", "reversed grid", "3.8:1.2:27"]),
        (["--voltages", "1.2:3.8:0"], ["--voltages", "empty grid"]),
        (["--pump-speeds", "200:1000"], ["--pump-speeds", "START:STOP:N"]),
        (["--pump-speeds=-200:1000:5"], ["pump speed must be a finite number in 0-3000 r/min"]),
        (["--voltages", "1.2:nan:5"], ["--voltages", "finite"]),
        (["--voltages", "1.2:3.8:x"], ["--voltages", "whole number"]),
    ],
)
def test_sweep_bad_grids_write_nothing(grid_args, fragments, tmp_path, capsys):
    out_file = tmp_path / "sweep.csv"
    status, _, err = run(["plant", "sweep", "--out", str(out_file), *grid_args], capsys)
    assert_one_line_error(status, err, *fragments)
    assert list(tmp_path.iterdir()) == []


def test_sweep_out_is_a_folder(tmp_path, capsys):
    status, _, err = run(["plant", "sweep", "--out", str(tmp_path)], capsys)
    assert_one_line_error(status, err, "--out", "folder")


def test_simulate_case_is_reproducible(tmp_path, capsys):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    for f in (a, b):
        assert run(["plant", "simulate", "--case", "case2", "--out", str(f), "--seed", "3"], capsys)[0] == 0
    assert a.read_bytes() == b.read_bytes()
    cols = read_csv(a)
    for name in ("time_s", "valve_voltage_v", "pump_speed_rpm", "motor_a_speed_rpm", "pump_pressure_pa"):
        assert name in cols
    assert cols["time_s"].size == 3001


def test_simulate_inputs_file(tmp_path, capsys):
    inputs = tmp_path / "in.csv"
    t = np.arange(0, 2, 0.01)
    inputs.write_text("time_s,valve_voltage_v,pump_speed_rpm\n" + "\n".join(f"{x:.2f},{2.0 if x < 1 else 3.0},600" for x in t))
    out = tmp_path / "out.csv"
    status, _, _ = run(["plant", "simulate", "--inputs", str(inputs), "--out", str(out), "--noise-std", "0"], capsys)
    assert status == 0
    cols = read_csv(out)
    assert cols["motor_a_speed_rpm"][-1] < cols["motor_a_speed_rpm"][0]  # closing A slows it


@pytest.mark.parametrize(
    "content, fragments",
    [
        ("time_s,valve_voltage_v\n0,2\n0.01,2\n", ["missing column", "pump_speed_rpm"]),
        ("time_s,valve_voltage_v,pump_speed_rpm\n0,2,500\n0.01,nan,500\n", ["valve voltage", "non-finite", "row 1"]),
        ("time_s,valve_voltage_v,pump_speed_rpm\n0,2,500\n0,2,500\n", ["strictly increasing"]),
        ("time_s,valve_voltage_v,pump_speed_rpm\n0,2,500\n0.01,2,abc\n", ["line 3", "pump_speed_rpm", "'abc'"]),
        ("", ["empty file"]),
        ("time_s,valve_voltage_v,pump_speed_rpm\n", ["no data rows"]),
    ],
)
def test_simulate_bad_inputs_file(content, fragments, tmp_path, capsys):
    inputs = tmp_path / "in.csv"
    inputs.write_text(content)
    out = tmp_path / "out.csv"
    status, _, err = run(["plant", "simulate", "--inputs", str(inputs), "--out", str(out)], capsys)
    assert_one_line_error(status, err, "--inputs", *fragments)
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def test_simulate_needs_a_source(tmp_path, capsys):
    status, _, err = run(["plant", "simulate", "--out", str(tmp_path / "o.csv")], capsys)
    assert_one_line_error(status, err, "--case", "--inputs")


def test_help_on_every_command(capsys):
    for argv in (["--help"], ["plant", "--help"], ["plant", "steady-state", "--help"], ["plant", "sweep", "--help"],
                 ["plant", "simulate", "--help"]):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0
        assert "usage:" in capsys.readouterr().out


def test_a_sweep_at_a_standing_pump_gives_no_percent_of_full_scale(tmp_path, capsys):
    """--pump-speeds 0:0:1 said 'largest hysteresis gap 42.7 % of full scale (0.0 r/min)': a share
    of a response spanning a few thousandths of a r/min."""
    from hwpts.cli import main

    assert main(["plant", "sweep", "--out", str(tmp_path / "s.csv"), "--pump-speeds", "0:0:1", "--voltages",
                 "1.5:3.5:5"]) == 0
    out = capsys.readouterr().out
    assert "no full scale" in out and "% of full scale" not in out
