"""Outputs never destroy anything: no output over an input, a link, a folder or a device; OS errors
are one line (exit 2); files get the umask's permissions; SIGTERM stops a run like Ctrl-C and leaves
nothing behind; a staging folder left by a killed run is removed by the next run."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

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
    # a model file is .json: the data file is refused before anything is read
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(data_csv)], "expected a .json file name")
    assert data_csv.read_bytes() == before
    model = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *FIT, "--out", str(model)]) == 0
    capsys.readouterr()
    saved = model.read_bytes()
    _one_line_error(capsys, ["predict", str(model), str(data_csv), "--out", str(model)], "expected a .csv or .parquet")
    assert model.read_bytes() == saved
    _one_line_error(capsys, ["predict", str(model), str(data_csv), "--out", str(data_csv)], "is the data file")
    assert data_csv.read_bytes() == before
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
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(real / "m.json")], "which is a file")
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


def test_an_interrupt_while_the_parser_is_built_is_an_interrupt(monkeypatch, capsys):
    # building the parser imports every command module (numpy and more): a Ctrl-C in that time
    # must already find the handlers in place, not end in a KeyboardInterrupt traceback
    import hwpts.cli as cli

    def slow_import():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1.0)  # the handler raises KeyboardInterrupt here
        raise AssertionError("the signal was not delivered")

    monkeypatch.setattr(cli, "build_parser", slow_import)
    before = signal.getsignal(signal.SIGINT)  # SIG_IGN when the tests run as a background job
    assert cli.main(["reproduce", "--quick"]) == 130
    assert capsys.readouterr().err == "hwpts: interrupted\n"
    assert signal.getsignal(signal.SIGINT) is before  # restored after the run


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


def test_a_signal_inside_the_folder_swap_lets_the_swap_complete(tmp_path, monkeypatch, capsys):
    # the earlier folder is moved aside, then the new one moved in: a Ctrl-C between the two
    # used to leave no folder at --out (and the next run deleted the one moved aside)
    from hwpts.io.atomic import INTERRUPTED
    from hwpts.io.folders import staged_folder

    out = tmp_path / "results"
    out.mkdir()
    (out / "summary.json").write_text('{"schema": "test/1", "run": 1}')
    (out / ".hwpts-files").write_text('["summary.json"]')  # the earlier run's list of its files
    real_replace = os.replace
    calls = []

    def replace_then_signal(src, dst):
        real_replace(src, dst)
        calls.append(dst)
        if len(calls) == 1:  # the earlier folder is aside, the new one not yet in place
            os.kill(os.getpid(), signal.SIGINT)

    def handler(args):
        with staged_folder(out, "test/1") as stage:
            (stage / "summary.json").write_text('{"schema": "test/1", "run": 2}')
        monkeypatch.setattr(os, "replace", real_replace)

    def patched(args):
        monkeypatch.setattr(os, "replace", replace_then_signal)
        return handler(args)

    assert _run_with_handler(monkeypatch, patched) == 0  # the commit completed: the run finished
    assert len(calls) == 2
    assert json.loads((out / "summary.json").read_text())["run"] == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]
    assert not INTERRUPTED.is_set()


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
    (["--ridge", "1e308"], "--ridge: expected a number from 0 to 1e+12"),
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


def _tree(root):
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None) for p in sorted(root.rglob("*"))}


def _start(argv, tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    return subprocess.Popen([sys.executable, "-m", "hwpts", *argv], stderr=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True, env=env)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL], ids=["SIGINT", "SIGTERM", "SIGKILL"])
def test_a_signal_during_reproduce_keeps_the_earlier_run(tmp_path, sig):
    out = tmp_path / "results"
    assert main(["reproduce", "--quick", "--out", str(out)]) == 0
    before = _tree(out)
    proc = _start(["reproduce", "--quick", "--out", str(out)], tmp_path)
    time.sleep(2.5)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before the signal (a very fast machine)")
    if sig == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
    else:
        assert proc.returncode == 130 and err.strip().splitlines()[-1] == "hwpts: interrupted", err
        assert "Traceback" not in err
    assert _tree(out) == before  # the earlier run is intact
    left = sorted(p.name for p in tmp_path.iterdir() if p.name not in ("results", "numba-cache"))
    if sig != signal.SIGKILL:
        assert left == []  # nothing left behind
    else:  # a killed run cannot clean up; the next run removes its staging folder
        assert main(["reproduce", "--quick", "--out", str(out)]) == 0
        assert sorted(p.name for p in tmp_path.iterdir() if p.name not in ("results", "numba-cache")) == []


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL],
                         ids=["SIGINT", "SIGTERM", "SIGHUP", "SIGKILL"])
def test_a_signal_during_a_sweep_keeps_the_earlier_file(tmp_path, sig):
    out = tmp_path / "sweep.csv"
    assert main(["plant", "sweep", "--out", str(out), "--voltages", "1.2:3.8:3", "--pump-speeds", "200:1000:3"]) == 0
    kept = out.read_bytes()
    proc = _start(["plant", "sweep", "--out", str(out), "--voltages", "1.2:3.8:500", "--pump-speeds", "200:1000:500"],
                  tmp_path)
    time.sleep(2.5)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the sweep finished before the signal (a very fast machine)")
    assert out.read_bytes() == kept
    if sig != signal.SIGKILL:
        assert proc.returncode == 130 and "Traceback" not in err
        assert err.strip().splitlines()[-1] == "hwpts: interrupted", err
    else:
        assert proc.returncode == -signal.SIGKILL
    # after the next run to the same file, no temporary file is left (a killed writer's included)
    assert main(["plant", "sweep", "--out", str(out), "--voltages", "1.2:3.8:3", "--pump-speeds", "200:1000:3"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) in (["sweep.csv"], ["numba-cache", "sweep.csv"])


def test_a_temporary_file_of_a_dead_writer_is_removed(tmp_path):
    from hwpts.io.atomic import write_text_atomic

    stale = tmp_path / ".m.json.999999999.abc123.json.tmp"  # no such process
    stale.write_text("half")
    alive = tmp_path / f".m.json.{os.getpid()}.xyz.json.tmp"  # this process: not touched
    alive.write_text("mine")
    write_text_atomic(tmp_path / "m.json", "{}")
    assert not stale.exists() and alive.exists()


def _without_root_rights():
    """A command prefix that runs hwpts without the rights that let root ignore file permissions
    (``setpriv`` drops CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH); nothing for a normal user."""
    import shutil

    if os.geteuid() != 0:
        return []
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        pytest.skip("running as root without setpriv: cannot drop the rights that bypass file permissions")
    caps = "-dac_override,-dac_read_search"
    return [setpriv, f"--bounding-set={caps}", f"--inh-caps={caps}"]


def test_permission_errors_are_one_line(tmp_path, data_csv):
    prefix = _without_root_rights()
    secret = tmp_path / "secret.csv"
    secret.write_bytes(data_csv.read_bytes())
    os.chmod(secret, 0o000)
    locked = tmp_path / "locked"
    locked.mkdir()
    os.chmod(locked, 0o555)
    try:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
        for argv, needle in (
            (["identify", str(secret), *FIT, "--out", str(tmp_path / "m.json")], "secret.csv"),
            (["identify", str(data_csv), *FIT, "--out", str(locked / "m.json")], "locked"),
            (["plant", "sweep", "--out", str(locked / "s.csv"), "--voltages", "1.2:3.8:3", "--pump-speeds",
              "200:1000:3"], "locked"),
            (["reproduce", "--quick", "--out", str(locked / "results")], "locked"),
        ):
            run = subprocess.run([*prefix, sys.executable, "-m", "hwpts", *argv], capture_output=True, text=True,
                                 env=env, timeout=120)
            lines = run.stderr.strip().splitlines()
            assert run.returncode == 2 and len(lines) == 1 and lines[0].startswith("hwpts: "), run.stderr
            assert needle in lines[0] and "Traceback" not in run.stderr
        assert list(locked.iterdir()) == [] and not (tmp_path / "m.json").exists()
    finally:
        os.chmod(locked, 0o755)
        os.chmod(secret, 0o644)


def test_parquet_outputs_read_back_and_dash_is_standard_output(tmp_path, data_csv, capsys):
    from hwpts.io.datasets import read_table

    model = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *FIT, "--out", str(model)]) == 0
    capsys.readouterr()
    out = tmp_path / "p.parquet"
    assert main(["predict", str(model), str(data_csv), "--out", str(out), "--mode", "one-step"]) == 0
    table = read_table(out, ["y", "y_predicted", "region"])
    assert out.read_bytes()[:4] == b"PAR1" and table["y_predicted"].shape == (400,)
    capsys.readouterr()
    assert main(["predict", str(model), str(data_csv), "--out", "-", "--mode", "one-step"]) == 0
    printed, err = capsys.readouterr()
    lines = printed.splitlines()
    assert lines[0] == "time_s,u1,u2,y,y_predicted,region" and len(lines) == 401 and "wrote to standard output (400 rows" in err
    np.testing.assert_allclose([float(r.split(",")[4]) for r in lines[1:]], table["y_predicted"], rtol=1e-9)
    sweep = tmp_path / "s.parquet"
    assert main(["plant", "sweep", "--out", str(sweep), "--voltages", "1.2:3.8:3", "--pump-speeds", "200:1000:3"]) == 0
    assert read_table(sweep, ["valve_voltage_v", "motor_a_speed_rpm"])["motor_a_speed_rpm"].shape == (27,)
    assert not (tmp_path / "-").exists()


def test_a_read_only_install_still_runs(tmp_path):
    """The numba kernels are cached beside the package; on a read-only install (and no writable
    home) the compiled code falls back without an error or a warning."""
    import shutil

    import hwpts

    prefix = _without_root_rights()
    site = tmp_path / "site"
    shutil.copytree(Path(hwpts.__file__).parent, site / "hwpts",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for path in [site, *site.rglob("*")]:
        os.chmod(path, 0o555 if path.is_dir() else 0o444)
    env = dict(os.environ, PYTHONPATH=str(site), HOME=str(tmp_path / "no-home"))
    env.pop("NUMBA_CACHE_DIR", None)
    try:
        run = subprocess.run([*prefix, sys.executable, "-m", "hwpts", "plant", "steady-state", "--valve-voltage", "2.4",
                              "--pump-speed", "700"], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert run.returncode == 0 and run.stderr == "", run.stderr
        assert json.loads(run.stdout)["motor_a_speed_rpm"] > 1000
        assert not list((site / "hwpts").rglob("__pycache__"))
        # ... and with a home that cannot be made (no cache folder for numba at all), identify
        # compiles its kernels too (it raised "cannot cache function '_alternate_kernel'")
        data = tmp_path / "d.csv"
        rng = np.random.default_rng(0)
        u = rng.uniform(-1, 1, 400)
        y = np.zeros(400)
        for k in range(1, 400):
            y[k] = 0.5 * y[k - 1] + u[k - 1] if y[k - 1] >= 0 else -0.4 * y[k - 1] + 2 * u[k - 1]
        data.write_text("u,y\n" + "".join(f"{a},{b}\n" for a, b in zip(u, y)))
        os.chmod(tmp_path, 0o777)
        locked = tmp_path / "locked"  # a home inside a folder nobody may write: it cannot be made
        locked.mkdir(mode=0o555)
        env["HOME"] = str(locked / "home")
        env.pop("XDG_CACHE_HOME", None)
        run = subprocess.run([*prefix, sys.executable, "-m", "hwpts", "identify", str(data), "--input", "u",
                              "--output", "y", "--na", "1", "--nb", "1", "--segmentation", "alternating",
                              "--regions", "2", "--out", str(tmp_path / "m.json")],
                             capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
        assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-500:]
    finally:
        for path in [site, *site.rglob("*")]:
            os.chmod(path, 0o755 if path.is_dir() else 0o644)
        if (tmp_path / "locked").exists():
            os.chmod(tmp_path / "locked", 0o755)


def test_a_summary_that_cannot_be_printed_leaves_no_model(tmp_path, monkeypatch, capsys):
    """The summary is printed before the model file is committed: a full disk behind stdout
    exits 2 with one line and writes no model (it was written, then the run said it failed)."""
    import errno

    from hwpts.identification.synthetic import make_system
    from hwpts.io.datasets import write_csv

    d = make_system(5, rng=0, n=300)
    write_csv(tmp_path / "d.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})

    class Full:
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

        def flush(self):
            pass

    monkeypatch.setattr("sys.stdout", Full())
    status = main(["identify", str(tmp_path / "d.csv"), "--input", "u1", "--input", "u2", "--output", "y",
                   "--na", "2", "--nb", "2", "--segmentation", "average", "--out", str(tmp_path / "m.json")])
    monkeypatch.undo()
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "standard output: cannot write the summary" in err[0]
    assert not (tmp_path / "m.json").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.csv"]


def test_a_long_output_name_is_written_and_a_failed_write_leaves_no_folder(tmp_path, monkeypatch):
    """A valid 240-character name was refused (the temporary name went over 255 bytes); the
    folders a failed write created were left behind."""
    from hwpts.io.atomic import write_text_atomic

    long_name = tmp_path / ("a" * 240 + ".json")
    write_text_atomic(long_name, "{}")
    assert long_name.read_text() == "{}"

    def fail():
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_text_atomic(tmp_path / "new" / "deeper" / "m.json", "{}", before_commit=fail)
    assert not (tmp_path / "new").exists()


def test_a_closed_stdout_still_writes_the_model_and_a_long_suffix_is_an_error(tmp_path, monkeypatch):
    from hwpts.errors import DataError
    from hwpts.io.atomic import write_text_atomic

    d = make_system(5, rng=0, n=300)
    write_csv(tmp_path / "d.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    monkeypatch.setattr("sys.stdout", None)  # started with >&-
    status = main(["identify", str(tmp_path / "d.csv"), "--input", "u1", "--input", "u2", "--output", "y",
                   "--na", "2", "--nb", "2", "--segmentation", "average", "--out", str(tmp_path / "m.json")])
    assert status == 0 and (tmp_path / "m.json").exists()
    # a table asked on standard output, with nowhere to go: one line before any work (a traceback)
    for args in (["predict", str(tmp_path / "m.json"), str(tmp_path / "d.csv"), "--out", "-"],
                 ["plant", "sweep", "--out", "-"]):
        assert main(args) == 2
    # a command whose result is what it prints: refused too (validate exited 0 having shown nothing),
    # unless it writes a figure
    for args in (["validate", str(tmp_path / "m.json"), str(tmp_path / "d.csv")],
                 ["residuals", str(tmp_path / "m.json"), str(tmp_path / "d.csv")],
                 ["plant", "steady-state", "--valve-voltage", "5", "--pump-speed", "1000"]):
        assert main(args) == 2
    assert main(["validate", str(tmp_path / "m.json"), str(tmp_path / "d.csv"), "--plot", str(tmp_path / "v.png")]) == 0
    assert (tmp_path / "v.png").exists()
    monkeypatch.undo()
    write_text_atomic(tmp_path / ("x." + "b" * 215), "{}")  # it looped for ever cutting the name
    assert (tmp_path / ("x." + "b" * 215)).read_text() == "{}"
    with pytest.raises(DataError, match="cannot write there"):
        write_text_atomic(tmp_path / ("x." + "b" * 300), "{}")  # too long for the file system


def test_run_folders_never_swallow_their_input_a_link_or_the_current_folder(tmp_path, monkeypatch, capsys):
    """control run --model DIR/model.json --out DIR deleted the model (the folder is replaced as a
    whole); a link as --out was replaced by a folder and left behind hidden; --out . did the work
    and then failed, leaving a staging folder."""
    run = tmp_path / "run"
    run.mkdir()
    (run / "model.json").write_text("{}")
    capsys.readouterr()
    assert main(["control", "run", "--scenario", "pump-step", "--model", str(run / "model.json"),
                 "--controllers", "pi", "--duration", "1", "--out", str(run)]) == 2
    assert "holds the model file" in capsys.readouterr().err
    assert (run / "model.json").read_text() == "{}"
    (tmp_path / "link").symlink_to(run)
    assert main(["reproduce", "--quick", "--out", str(tmp_path / "link")]) == 2
    assert "is a symbolic link" in capsys.readouterr().err and (tmp_path / "link").is_symlink()
    monkeypatch.chdir(run)
    assert main(["reproduce", "--quick", "--out", "."]) == 2
    assert "is (or holds) the current folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "run"]


def test_a_stop_after_the_commit_says_the_file_was_written(tmp_path, monkeypatch, capsys):
    """A Ctrl-C landing just after the model file was committed cannot undo it: the run ends as
    interrupted (130) and says which file it wrote (it said 'interrupted' beside a complete file)."""
    import hwpts.io.models as models

    d = make_system(5, rng=0, n=300)
    write_csv(tmp_path / "d.csv", {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    save = models.save_model

    def save_then_stop(*args, **kwargs):
        save(*args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(models, "save_model", save_then_stop)
    status = main(["identify", str(tmp_path / "d.csv"), "--input", "u1", "--input", "u2", "--output", "y",
                   "--na", "2", "--nb", "2", "--segmentation", "average", "--out", str(tmp_path / "m.json")])
    err = capsys.readouterr().err.strip()
    assert status == 130 and (tmp_path / "m.json").exists()
    assert err == f"hwpts: interrupted after writing {tmp_path / 'm.json'}"


def test_a_signal_while_the_cli_module_is_half_imported_is_an_interrupt(monkeypatch):
    """The console script's handler reads ``hwpts.cli._SETTLED``; a signal in the first
    milliseconds finds ``hwpts.cli`` in ``sys.modules`` without it (partly imported) and raised
    AttributeError there, a traceback and exit 1 (``timeout -s TERM 0.03 hwpts validate ...``, 8
    runs of 8). Without the flag the run has not begun: the signal is an interrupt."""
    import types

    from hwpts import _console

    monkeypatch.setitem(sys.modules, "hwpts.cli", types.ModuleType("hwpts.cli"))
    with pytest.raises(KeyboardInterrupt):
        _console._interrupt(signal.SIGTERM, None)


def test_a_full_disk_behind_standard_output_names_the_stream_and_the_files_written(monkeypatch, capsys, tmp_path):
    """A report printed after the output was committed, to a stdout that cannot take it
    (``hwpts predict ... --out p.csv >/dev/full``): one line naming standard output and the file,
    complete all the same, exit 2 (it said ``hwpts: error: No space left on device``). A closed
    pipe (``| head``) stays no error."""
    import errno

    out = tmp_path / "p.csv"

    class Full:
        def write(self, text):
            raise OSError(errno.ENOSPC, "No space left on device")

        def flush(self):
            pass

    def handler(args):
        out.write_text("t,y\n0,1\n")
        monkeypatch.setattr(sys, "stdout", Full())
        print("predicted 1 sample")
        return 0

    assert _run_with_handler(monkeypatch, handler, ("fake", "--out", str(out))) == 2
    assert capsys.readouterr().err == (f"hwpts: error: standard output: cannot write (No space left on device); "
                                       f"{out} was written in full\n")

    def piped(args):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    assert _run_with_handler(monkeypatch, piped) == 0


def test_a_run_under_nohup_outlives_a_closed_terminal(tmp_path):
    """SIGHUP stops a run as Ctrl-C does, unless the run was started to outlive its terminal
    (`nohup`, which ignores SIGHUP): then it is left alone, as before the handler existed."""
    out = tmp_path / "sweep.csv"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    proc = subprocess.Popen([sys.executable, "-m", "hwpts", "plant", "sweep", "--out", str(out), "--voltages",
                             "1.2:3.8:200", "--pump-speeds", "200:1000:150"], stderr=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    time.sleep(1.5)
    if proc.poll() is not None:
        pytest.skip("the sweep finished before the signal (a very fast machine)")
    proc.send_signal(signal.SIGHUP)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0 and out.exists(), err


def test_a_path_that_is_not_utf8_is_refused_in_one_line(tmp_path, data_csv, capsys):
    """An output name with a byte that is not UTF-8 ended in UnicodeEncodeError from the atomic
    writer (identify, predict, export, plant simulate, validate --plot, reproduce at its report):
    refused; so is an input's (its name in a figure title ended in matplotlib's TypeError, then was
    drawn escaped, but went into identify's JSON summary as a lone surrogate that strict readers
    refuse; the README says such paths are refused)."""
    bad = os.fsdecode(b"m\xff.json")
    _one_line_error(capsys, ["identify", str(data_csv), *FIT, "--out", str(tmp_path / bad)],
                    "m\\xff.json': the path holds bytes that are not UTF-8")
    assert not list(tmp_path.glob("m*"))
    model = tmp_path / "m.json"
    assert main(["identify", str(data_csv), *FIT, "--out", str(model)]) == 0
    capsys.readouterr()
    odd = tmp_path / os.fsdecode(b"d\xff.csv")
    odd.write_bytes(data_csv.read_bytes())
    _one_line_error(capsys, ["validate", str(model), str(odd), "--plot", str(tmp_path / "v.png")],
                    "DATA '" + str(tmp_path) + "/d\\xff.csv': the path holds bytes that are not UTF-8")
    _one_line_error(capsys, ["identify", str(odd), *FIT, "--out", str(tmp_path / "m2.json")], "DATA '")
    assert not (tmp_path / "v.png").exists() and not (tmp_path / "m2.json").exists()
    _one_line_error(capsys, ["plant", "simulate", "--case", "case1", "--out", str(tmp_path / os.fsdecode(b"s\xff.csv"))],
                    "the path holds bytes that are not UTF-8")


def test_a_reader_that_stops_early_gets_no_wrote_line(tmp_path, data_csv):
    """``hwpts predict ... --out - | head -c 100``: Python's buffered stdout dropped the rest of a
    large write that the pipe took only in part, without an error, and predict said "wrote to
    standard output (... rows ...)" beneath 100 bytes; written through the descriptor, the closed
    pipe ends the run as every closed pipe does (exit 0, nothing said). A reader that takes it all
    gets every row."""
    big = tmp_path / "big.csv"
    d = make_system(5, rng=1, n=40_000)
    write_csv(big, {"u1": d.inputs[:, 0], "u2": d.inputs[:, 1], "y": d.output})
    model = tmp_path / "m.json"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    run = [sys.executable, "-m", "hwpts"]
    subprocess.run([*run, "identify", str(data_csv), *FIT, "--out", str(model)], check=True, env=env,
                   capture_output=True)
    proc = subprocess.Popen([*run, "predict", str(model), str(big), "--out", "-"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env)
    assert len(proc.stdout.read(100)) == 100
    proc.stdout.close()  # the reader stops: the rest of the table (~3 MB) meets a closed pipe
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 0 and "wrote" not in err and "Traceback" not in err, err
    whole = subprocess.run([*run, "predict", str(model), str(big), "--out", "-"], capture_output=True, env=env)
    assert whole.returncode == 0 and whole.stdout.decode().count("\n") == 40_001
    assert "wrote to standard output (40000 rows" in whole.stderr.decode()
