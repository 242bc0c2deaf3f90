"""Monte-Carlo study: perturbed plants x wind seeds x controllers, mapped over Dask.

Each task is one (plant, wind seed): the scenario on that plant, every controller on it, one row of
metrics per controller. The controllers are designed from one model bank (identified on the nominal
test bed), so the study measures how well they hold up on plants the model was not identified on.
Tasks share nothing mutable; they run on a local Dask cluster by default or on an existing
scheduler (``address``).

Plant tolerances (uniform, independent, relative to the test bed unless stated):
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hwpts.errors import DataError, ParameterError

PLANT_TOLERANCES = {
    "bulk_modulus": 0.20,
    "discharge_coefficient": 0.05,
    "max_orifice_area": 0.05,
    "pump_displacement": 0.03,
    "motor_a_displacement": 0.03,
    "motor_a_leakage": 0.20,
    "motor_a_inertia": 0.20,
    "motor_a_damping": 0.20,
    "motor_a_load_torque": 0.10,
    "aux_opening_pressure": 0.05,
    "droop_gain": 0.15,
    "hysteresis_half_width": 0.20,
    "generator_slip_gain": 0.30,
}
"""Relative half-width of the uniform spread of each parameter (manufacturing and assembly spread of
the components, oil temperature for the bulk modulus and leakage, wear for the valve's play)."""

__doc__ += "".join(f"\n- ``{k}``: +-{v * 100:g} %" for k, v in PLANT_TOLERANCES.items())

CONNECT_TIMEOUT_S = 10.0
"""How long to try to reach a Dask scheduler given by address [s]."""

TARGETS = {"rms_error_percent": 1.0, "within_1_percent_share": 0.95, "rms_reduction_vs_pi": 0.30}
"""The turbulence targets a controller must meet on a (plant, seed): RMS error <= 1 %, within +-1 %
for >= 95 % of the reachable time, RMS at least 30 % below the PI baseline's on the same run."""


def perturbed_parameters(nominal, index: int, seed: int):
    """Plant ``index`` of the study: every toleranced parameter drawn uniformly within its tolerance.
    Plant 0 is the nominal test bed."""
    if index == 0:
        return nominal
    rng = np.random.default_rng([seed, index])
    changes = {k: getattr(nominal, k) * (1.0 + tol * rng.uniform(-1.0, 1.0)) for k, tol in PLANT_TOLERANCES.items()}
    return nominal.replace(**changes)


def run_task(model_doc: dict, model_sample_time: float, half_width: float, scenario_name: str, plant_index: int,
             wind_seed: int, study_seed: int, controllers, duration=None) -> list[dict]:
    """One (plant, seed): rows of metrics, one per controller (runs on a Dask worker)."""
    from hwpts.control.controllers import make_controller
    from hwpts.control.loop import reachable_mask, run_loop
    from hwpts.control.metrics import compute_metrics
    from hwpts.control.model import ModelBank
    from hwpts.control.scenarios import build_scenario

    bank = ModelBank(model_doc, model_sample_time)
    scenario = build_scenario(scenario_name, seed=wind_seed, duration=duration)
    scenario.parameters = perturbed_parameters(scenario.parameters, plant_index, study_seed)
    reach = reachable_mask(scenario)
    rows = []
    for name in controllers:
        c = make_controller(name, bank, half_width, scenario)
        result = run_loop(scenario, c, seed=wind_seed, reachable=reach)
        m = compute_metrics(scenario, result, c.has_modes)
        row = {"plant": plant_index, "seed": wind_seed, "controller": name, "reachable_share": float(np.mean(reach))}
        for k, v in m.items():
            if k == "step_time_ms":
                row["step_time_median_ms"], row["step_time_max_ms"] = v["median"], v["max"]
            else:
                row[k] = math.nan if v is None else float(v)
        rows.append(row)
    return rows


@dataclass
class StudyResult:
    rows: list
    summary: dict


def summarize(rows: list[dict], controllers, n_plants: int, n_seeds: int) -> dict:
    """Per controller: share of plants on which it meets the targets on every seed (and of runs)."""
    by = {(r["plant"], r["seed"], r["controller"]): r for r in rows}
    out = {}
    for name in controllers:
        runs, plants_ok = 0, 0
        passed_runs = 0
        rms = []
        for p in range(n_plants):
            ok_all = True
            for s in range(n_seeds):
                r = by.get((p, s, name))
                pi = by.get((p, s, "pi"))
                if r is None:
                    ok_all = False
                    continue
                runs += 1
                rms.append(r["rms_error_percent"])
                ok = (r["rms_error_percent"] <= TARGETS["rms_error_percent"]
                      and r["within_1_percent_share"] >= TARGETS["within_1_percent_share"])
                if pi is not None and name != "pi":
                    ok = ok and r["rms_error_percent"] <= (1 - TARGETS["rms_reduction_vs_pi"]) * pi["rms_error_percent"]
                passed_runs += ok
                ok_all = ok_all and ok
            plants_ok += ok_all
        out[name] = {"plants_meeting_targets_share": plants_ok / n_plants if n_plants else None,
                     "runs_meeting_targets_share": passed_runs / runs if runs else None,
                     "median_rms_error_percent": float(np.nanmedian(rms)) if rms else None,
                     "worst_rms_error_percent": float(np.nanmax(rms)) if rms else None}
    return out


def is_address(text: str) -> bool:
    """Whether ``text`` is a scheduler address hwpts connects to: ``tcp://HOST:PORT`` or ``HOST:PORT``."""
    import re

    import socket

    found = re.fullmatch(r"(tcp://)?([A-Za-z0-9_.\-\[\]:]+):(\d{1,5})", str(text))
    if not found or not 1 <= int(found.group(3)) <= 65535:  # a port number (99999 waited 10 s to fail)
        return False
    host = found.group(2)
    if re.fullmatch(r"[\d.]+", host):  # numbers and dots: an IPv4 address (256.1.1.1 waited 10 s to fail),
        try:  # in any form the system's resolver takes (127.1 too)
            socket.inet_aton(host)
        except OSError:
            return False
    return True


def _connect(Client, scheduler: str):
    """A client of the Dask scheduler at ``scheduler`` (``tcp://host:port`` or ``host:port``), or one
    line saying why not. The whole handshake has a deadline: a server that accepts the connection
    and then says nothing (not a scheduler) held the run for as long as it stayed open."""
    import threading

    if not is_address(scheduler):
        raise DataError(f"--scheduler {scheduler!r}: expected a Dask scheduler's address tcp://HOST:PORT")
    result: dict = {}

    def attempt():
        try:
            result["client"] = Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
        except BaseException as error:  # noqa: BLE001 - reported below as one line
            result["error"] = error

    worker = threading.Thread(target=attempt, daemon=True)
    worker.start()
    worker.join(2 * CONNECT_TIMEOUT_S)
    if "client" in result:
        return result["client"]
    error = result.get("error")
    if error is None:
        why = f"no scheduler answered within {2 * CONNECT_TIMEOUT_S:g} s"
    elif isinstance(error, MemoryError):
        why = "what answered is not a Dask scheduler"
    elif isinstance(error, KeyboardInterrupt):
        raise error
    else:
        why = f"{type(error).__name__}: {str(error).splitlines()[0] if str(error) else ''}"
    raise DataError(f"--scheduler {scheduler!r}: cannot reach a Dask scheduler there ({why})")


def _local_cluster(LocalCluster, n_workers: int | None):
    """A local Dask cluster that leaves Ctrl-C to hwpts. A Ctrl-C at the terminal reaches the
    whole process group: each worker process printed its own traceback and the nanny its warnings
    about cancelled tasks and killed workers. SIGINT is blocked while the cluster starts: the
    workers inherit the blocked mask through fork and exec (and Python leaves it alone), as do
    the cluster's threads, which spawn any later worker, so only hwpts sees a Ctrl-C; the
    cluster's own log is silenced below critical (at errors, a worker whose heartbeat raced the
    scheduler's close after a Ctrl-C printed its traceback, seen in one CI run; a task's
    failure or a lost worker still reaches hwpts as the exception of its result). A Ctrl-C or
    SIGTERM in the second or two the cluster takes to start is held until it has started
    (stopped half-way, the cluster left its workers' semaphores to multiprocessing's resource
    tracker, which reported them as leaked after hwpts's last line); the cluster is then closed
    and the signal delivered to the handler it had."""
    import gc
    import logging
    import signal
    import threading
    from multiprocessing import resource_tracker

    def start():
        return LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.CRITICAL)

    from hwpts._signals import interrupt_signals

    held = interrupt_signals()
    previous = {sig: signal.getsignal(sig) for sig in held}
    if (threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask")
            or any(handler is None for handler in previous.values())):  # handlers not ours to move
        return start()
    # multiprocessing's resource tracker, started from the cluster's event-loop thread, would
    # unblock SIGINT there (it blocks and unblocks it around its own spawn): started first here
    resource_tracker.ensure_running()
    caught: list = []
    held_mask = set(held)
    sigint = {signal.SIGINT}

    def deliver(pending: bool):
        """The handlers and the mask as they were, then the signals recorded meanwhile to their
        own handlers (hwpts's raise KeyboardInterrupt); a SIGINT held by the mask (``pending``)
        reaches its handler when the mask goes back."""
        signal.pthread_sigmask(signal.SIG_BLOCK, held_mask)  # none delivered while the handlers go back
        try:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)
        for sig in dict.fromkeys(caught):
            if previous[sig] is not signal.SIG_IGN and not (pending and sig == signal.SIGINT):
                signal.raise_signal(sig)

    for sig in held:
        signal.signal(sig, lambda signum, frame: caught.append(signum))
    old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, sigint)
    try:
        cluster = start()
    except BaseException:  # a SIGTERM to the process group stops the starting workers too
        deliver(signal.SIGINT in signal.sigpending() and signal.SIGINT not in old_mask)
        raise
    pending = signal.SIGINT in signal.sigpending() and signal.SIGINT not in old_mask  # a caller's own is its own
    if pending:
        caught.append(signal.SIGINT)
    stopping = any(previous[sig] is not signal.SIG_IGN for sig in caught)
    try:
        if stopping:
            # closed and collected now: its workers' queues hold semaphores that multiprocessing's
            # resource tracker, finding them at the exit, reports as leaked (a line after hwpts's)
            try:
                cluster.close()
            finally:
                cluster = None
                gc.collect()
    finally:
        try:
            deliver(pending)
        except BaseException:
            if cluster is not None:
                cluster.close()
            raise
    if stopping:  # handlers that recorded the signal without raising
        raise KeyboardInterrupt
    return cluster


def run_study(model_doc: dict, model_sample_time: float, half_width: float, n_plants: int, n_seeds: int,
              controllers, scenario_name: str = "turbulence-a", study_seed: int = 0, scheduler: str | None = None,
              duration=None, progress: bool = False, n_workers: int | None = None) -> StudyResult:
    """Map (plant, seed) tasks over a Dask cluster (local unless ``scheduler`` is an address)."""
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise ParameterError("the study runs on Dask: install it with pip install 'hwpts[study]' "
                             "(dask[distributed])") from None
    if n_plants < 1 or n_seeds < 1:
        raise ParameterError(f"--plants and --seeds must be >= 1, got {n_plants} and {n_seeds}")
    from tqdm import tqdm

    cluster = None
    try:
        if scheduler:
            client = _connect(Client, scheduler)
        else:
            cluster = _local_cluster(LocalCluster, n_workers)
            client = Client(cluster)
        try:
            doc = client.scatter(model_doc, broadcast=True)
            futures = [client.submit(run_task, doc, model_sample_time, half_width, scenario_name, p, s, study_seed,
                                     list(controllers), duration, pure=False)
                       for p in range(n_plants) for s in range(n_seeds)]
            rows = []
            with tqdm(total=len(futures), desc="study", unit="run", disable=not progress, leave=False) as bar:
                for fut in as_completed(futures):
                    rows.extend(fut.result())
                    bar.update(1)
        finally:
            client.close()
    finally:
        if cluster is not None:
            cluster.close()
    rows.sort(key=lambda r: (r["plant"], r["seed"], list(controllers).index(r["controller"])))
    return StudyResult(rows, summarize(rows, controllers, n_plants, n_seeds))
