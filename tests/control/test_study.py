"""``hwpts control study`` on Dask: a local cluster, and a scheduler + worker started on the loopback."""

import json
import subprocess
import sys
import time

import pytest

from hwpts.cli import main

pytest.importorskip("distributed")


def _study(tmp_path, model_file, *extra):
    out = tmp_path / "study"
    code = main(["control", "study", "--plants", "2", "--seeds", "1", "--duration", "8", "--controllers", "pi,scheduled",
                 "--model", str(model_file), "--out", str(out), *extra])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    import pyarrow.parquet as pq

    table = pq.read_table(out / "results.parquet").to_pydict()
    return summary, table


def _check(summary, table):
    assert summary["schema"] == "hwpts.control-study/1"
    assert summary["duration_s"] == 8.0 and summary["run"]["command"].startswith("hwpts control study --plants 2")
    assert set(summary["controllers"]) == {"pi", "scheduled"}
    assert len(table["controller"]) == 2 * 1 * 2
    assert sorted(set(table["plant"])) == [0, 1]
    for s in summary["controllers"].values():
        assert 0.0 <= s["plants_meeting_targets_share"] <= 1.0


@pytest.mark.slow
def test_study_on_a_local_cluster(tmp_path, paper_model_file):
    summary, table = _study(tmp_path, paper_model_file, "--workers", "2")
    _check(summary, table)
    assert summary["scheduler"] == "local cluster"


@pytest.mark.slow
def test_study_through_a_scheduler_on_the_loopback(tmp_path, paper_model_file):
    file = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                                  "--no-dashboard", "--scheduler-file", str(file)],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        for _ in range(200):
            if file.exists() and file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        worker = subprocess.Popen([sys.executable, "-m", "dask", "worker", "--scheduler-file", str(file),
                                   "--nworkers", "1", "--nthreads", "1", "--no-dashboard"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        summary, table = _study(tmp_path, paper_model_file, "--scheduler", address)
        _check(summary, table)
        assert summary["scheduler"] == address
    finally:
        for proc in (worker, scheduler):
            if proc is not None:
                proc.terminate()
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()


def test_unreachable_scheduler_is_one_line(tmp_path, capsys, paper_model_file, monkeypatch):
    monkeypatch.setattr("hwpts.control.study.CONNECT_TIMEOUT_S", 1.0)
    code = main(["control", "study", "--plants", "1", "--seeds", "1", "--duration", "5", "--controllers", "pi",
                 "--model", str(paper_model_file), "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--scheduler" in err


def test_the_pi_baseline_is_always_run(tmp_path, capsys, paper_model_file):
    """Without pi in --controllers the '30 % below PI' target was dropped in silence: the same
    controller met the targets or not as pi was listed. pi is added, and said so."""
    out = tmp_path / "study"
    assert main(["control", "study", "--plants", "1", "--seeds", "1", "--duration", "3", "--controllers", "scheduled",
                 "--model", str(paper_model_file), "--out", str(out)]) == 0
    assert "pi added to --controllers" in capsys.readouterr().err
    assert set(json.loads((out / "summary.json").read_text())["controllers"]) == {"pi", "scheduled"}


def _spawned_children(pid: int) -> list[int]:
    """Process ids of the multiprocessing children (Dask workers) of ``pid`` (Linux /proc)."""
    import pathlib

    found = []
    for status in pathlib.Path("/proc").glob("[0-9]*/status"):
        try:
            fields = dict(line.split(":\t", 1) for line in status.read_text().splitlines() if ":\t" in line)
            cmdline = (status.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if fields.get("PPid", "").strip() == str(pid) and b"multiprocessing.spawn" in cmdline:
            found.append(int(status.parent.name))
    return found


def _signal_a_study(tmp_path, model_file, sig, workers_seen, settle):
    """Run ``hwpts control study`` on a local cluster in its own process group, send ``sig`` to
    the group once ``workers_seen`` worker processes were spawned and ``settle`` seconds passed;
    the exit status and standard error."""
    import os
    import signal

    proc = subprocess.Popen([sys.executable, "-m", "hwpts", "control", "study", "--plants", "50", "--seeds", "2",
                             "--duration", "60", "--workers", "2", "--model", str(model_file),
                             "--out", str(tmp_path / "study")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True, cwd=tmp_path)
    try:
        deadline = time.monotonic() + 120
        while len(_spawned_children(proc.pid)) < workers_seen and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.01)
        assert len(_spawned_children(proc.pid)) >= workers_seen, "the local cluster's workers never started"
        time.sleep(settle)
        os.killpg(proc.pid, sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, err.decode()


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to see the workers start")
def test_ctrl_c_at_the_terminal_stops_a_study_in_one_line(tmp_path, paper_model_file):
    """A terminal's Ctrl-C reaches the whole process group, Dask's worker processes included: they
    leave it to hwpts (no traceback from any of them), and the run ends as any interrupted run."""
    import signal

    status, text = _signal_a_study(tmp_path, paper_model_file, signal.SIGINT, 2, 3)  # the workers run tasks
    assert status == 130
    assert "Traceback" not in text and "WARNING" not in text, text
    assert text.strip().splitlines()[-1] == "hwpts: interrupted"
    assert not (tmp_path / "study").exists()


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc to see the workers start")
@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_while_the_local_cluster_starts_is_not_lost(tmp_path, paper_model_file, name):
    """A Ctrl-C in the second or two the cluster takes to start (the workers just spawned) was
    ignored: the study ran on. It now ends the run as any interrupt, the workers silent, and
    nothing after hwpts's line (a cluster stopped half-way left semaphores that multiprocessing's
    resource tracker reported as leaked); the same for a SIGTERM to the process group."""
    import signal

    status, text = _signal_a_study(tmp_path, paper_model_file, getattr(signal, name), 1, 0)  # workers importing
    assert status == 130, text
    assert "Traceback" not in text and "KeyboardInterrupt" not in text and "WARNING" not in text, text
    assert text.strip().splitlines()[-1] == "hwpts: interrupted", text
    assert not (tmp_path / "study").exists()


class _FakeCluster:
    def __init__(self, during=None, **kwargs):
        self.closed = False
        if during is not None:
            during()

    def close(self):
        self.closed = True


@pytest.mark.skipif(not hasattr(__import__("signal"), "pthread_sigmask"), reason="POSIX signal masks")
def test_the_local_cluster_start_restores_the_handlers_and_the_mask():
    import signal

    from hwpts.control.study import _local_cluster

    def handler(signum, frame):
        raise KeyboardInterrupt

    before = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        cluster = _local_cluster(_FakeCluster, 2)
        assert not cluster.closed
        assert signal.getsignal(signal.SIGINT) is handler and signal.getsignal(signal.SIGTERM) is handler
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])
        made = []

        def start(**kwargs):  # the signal arrives while the cluster starts: held, then delivered
            made.append(_FakeCluster(during=lambda: signal.raise_signal(signal.SIGTERM)))
            return made[-1]

        with pytest.raises(KeyboardInterrupt):
            _local_cluster(start, 2)
        assert made[0].closed
        assert signal.getsignal(signal.SIGTERM) is handler
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])
    finally:
        for sig, old in before.items():
            signal.signal(sig, old)


class _StuckCluster(_FakeCluster):
    def close(self):
        raise RuntimeError("close timed out")


@pytest.mark.skipif(not hasattr(__import__("signal"), "pthread_sigmask"), reason="POSIX signal masks")
def test_the_handlers_and_the_mask_come_back_whatever_fails():
    """A cluster whose close fails after a held signal, and a caller that had SIGINT blocked: the
    handlers and the caller's mask come back (a failed close left Ctrl-C disabled)."""
    import signal

    from hwpts.control.study import _local_cluster

    def handler(signum, frame):
        raise KeyboardInterrupt

    before = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        with pytest.raises((KeyboardInterrupt, RuntimeError)):
            _local_cluster(lambda **kw: _StuckCluster(during=lambda: signal.raise_signal(signal.SIGTERM)), 2)
        assert signal.getsignal(signal.SIGINT) is handler and signal.getsignal(signal.SIGTERM) is handler
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})  # the caller's own block is kept
        try:
            assert not _local_cluster(_FakeCluster, 2).closed
            assert signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])
        finally:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    finally:
        for sig, old in before.items():
            signal.signal(sig, old)
