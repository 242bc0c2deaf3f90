"""Outputs never destroy anything: no output over an input, a link, a folder or a device; OS errors
are one line (exit 2); files get the umask's permissions; SIGTERM stops a run like Ctrl-C and leaves
nothing behind; a staging folder left by a killed run is removed by the next run."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from hwpts.cli import main
from hwpts.identification.synthetic import make_system
from hwpts.io.datasets import write_csv


@pytest.fixture
def data_csv(tmp_path):
    d = make_system(5, rng=0, n=400)
    path = tmp_path / "s5.csv"
    write_csv(path, {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    return path


FIT = ["--input", "u1", "--input", "u2", "--output", "y", "--na", "2", "--nb", "2", "--segmentation", "average"]


def _one_line_error(capsys, argv, match):
    code = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("hwpts: error:"), err
    assert "Traceback" not in err and match in lines[0], lines[0]


def test_output_over_an_input_is_refused(tmp_path, data_csv, capsys):
    before = data_csv.read_bytes()
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(data_csv)], "would destroy the input")
    assert data_csv.read_bytes() == before
    model = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *FIT, "--out", str(model)]) == 0
    capsys.readouterr()
    saved = model.read_bytes()
    _one_line_error(capsys, ["predict", str(model), str(data_csv), "--out", str(model)], "is the model file")
    assert model.read_bytes() == saved
    inputs = tmp_path / "inp.csv"
    write_csv(inputs, {"time_s": np.arange(50) * 0.01, "valve_voltage_v": np.full(50, 2.0),
                       "pump_speed_rpm": np.full(50, 600.0)})
    kept = inputs.read_bytes()
    _one_line_error(capsys, ["plant", "simulate", "--inputs", str(inputs), "--out", str(inputs)], "is the inputs file")
    assert inputs.read_bytes() == kept


def test_links_folders_and_bad_parents_are_refused(tmp_path, data_csv, capsys):
    real = tmp_path / "real.json"
    real.write_text("keep")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(link)], "symbolic link")
    assert link.is_symlink() and real.read_text() == "keep"
    folder = tmp_path / "folder"
    folder.mkdir()
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(folder)], "is a folder")
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(real / "m.json")], "cannot write there")
    assert real.read_text() == "keep"
    assert not [p for p in tmp_path.rglob(".*") if p.name.endswith(".tmp")]


def test_files_get_the_umask_permissions(tmp_path, data_csv, capsys):
    old = os.umask(0o022)
    try:
        out = tmp_path / "m.json"
        assert main(["identify", str(data_csv), *FIT, "--out", str(out)]) == 0
    finally:
        os.umask(old)
    assert (out.stat().st_mode & 0o777) == 0o644


@pytest.mark.parametrize("delay", [1.0, 2.2, 3.0])
def test_sigterm_stops_a_sweep_and_leaves_nothing(tmp_path, delay):
    # a fresh numba cache: the signal may land while a kernel compiles (inside a C callback), which
    # once gave a traceback and exit 1 on a clean clone
    out = tmp_path / "sweep.csv"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    proc = subprocess.Popen([sys.executable, "-m", "hwpts", "plant", "sweep", "--out", str(out),
                             "--voltages", "1.2:3.8:500", "--pump-speeds", "200:1000:500"],
                            stderr=subprocess.PIPE, text=True, env=env)
    time.sleep(delay)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    if proc.returncode == 0 and "interrupted" not in err:
        pytest.skip("the sweep finished before the signal (a very fast machine)")
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert err.strip().splitlines() == ["hwpts: interrupted"]
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] in ([], ["numba-cache"])


def _run_with_handler(monkeypatch, handler, argv=("fake",)):
    """Run :func:`hwpts.cli.main` with one fake command whose handler is ``handler``."""
    import hwpts.cli as cli

    def parser():
        p = cli.ArgumentParser(prog="hwpts")
        sub = p.add_subparsers(dest="command", parser_class=cli.ArgumentParser)
        fake = sub.add_parser("fake")
        fake.add_argument("--out")
        fake.set_defaults(handler=handler)
        return p

    monkeypatch.setattr(cli, "build_parser", parser)
    return cli.main(list(argv))


def test_an_interrupt_swallowed_by_a_library_is_still_an_interrupt(monkeypatch, capsys):
    from hwpts.io.atomic import INTERRUPTED

    def handler(args):  # what numba does when the signal lands in its C callback
        INTERRUPTED.set()
        sys.unraisablehook(type("U", (), {"exc_type": KeyboardInterrupt, "exc_value": KeyboardInterrupt(),
                                          "exc_traceback": None, "err_msg": "Exception ignored", "object": None})())
        raise RuntimeError("no compiled object yet")

    assert _run_with_handler(monkeypatch, handler) == 130
    assert capsys.readouterr().err == "hwpts: interrupted\n"


def test_no_output_is_committed_after_an_interrupt(tmp_path, monkeypatch, capsys):
    from hwpts.io.atomic import INTERRUPTED, write_text_atomic
    from hwpts.io.folders import staged_folder

    out = tmp_path / "m.json"

    def handler(args):  # the interrupt was swallowed and the run went on to write its output
        INTERRUPTED.set()
        write_text_atomic(out, "{}")

    assert _run_with_handler(monkeypatch, handler) == 130
    assert not out.exists() and not list(tmp_path.iterdir())

    def folder_handler(args):
        with staged_folder(tmp_path / "results", "test/1") as stage:
            INTERRUPTED.set()
            (stage / "summary.json").write_text("{}")

    assert _run_with_handler(monkeypatch, folder_handler) == 130
    assert not list(tmp_path.iterdir())
    assert not INTERRUPTED.is_set()  # cleared when main returns: library calls after it still write
    # and a later run in the same process is not affected by the earlier interrupt
    assert _run_with_handler(monkeypatch, lambda args: write_text_atomic(out, "{}")) == 0 and out.exists()


def test_a_killed_runs_staging_folder_is_removed_by_the_next_run(tmp_path):
    from hwpts.io.folders import PID_FILE, staged_folder

    out = tmp_path / "results"
    stale = tmp_path / ".results.new-dead"
    stale.mkdir()
    (stale / PID_FILE).write_text("999999999")  # no such process
    with staged_folder(out, "test/1") as stage:
        (stage / "summary.json").write_text('{"schema": "test/1"}')
    assert not stale.exists() and (out / "summary.json").exists()
    assert not (out / PID_FILE).exists()


@pytest.mark.parametrize("extra, match", [
    (["--seed", "-1"], "argument --seed: expected a whole number >= 0, got '-1'"),
    (["--ridge", "1e308"], "numerical failure"),
    (["--ridge", "-1"], "argument --ridge"),
])
def test_values_checked_at_the_edge(tmp_path, data_csv, capsys, extra, match):
    out = tmp_path / "m.json"
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, *extra, "--out", str(out)], match)
    assert not out.exists()


def test_a_sweep_grid_too_large_for_memory_is_refused_before_allocating(tmp_path, capsys):
    out = tmp_path / "s.csv"
    _one_line_error(capsys, ["plant", "sweep", "--out", str(out), "--voltages", "1.2:3.8:50000",
                             "--pump-speeds", "200:1000:50000"], "2,500,000,000 operating points")
    assert not out.exists()


def test_validate_json_is_strict_when_the_free_run_diverges():
    """JSON has no NaN or Infinity: a diverged fit is null."""
    from hwpts.commands._args import json_text

    text = json_text({"fit_percent": float("nan"), "rmse": float("inf"), "n": 3, "fits": [1.0, float("-inf")]})
    import json

    assert json.loads(text) == {"fit_percent": None, "rmse": None, "n": 3, "fits": [1.0, None]}
    assert "NaN" not in text and "Infinity" not in text
