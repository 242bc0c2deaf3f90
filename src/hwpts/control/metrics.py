"""Closed-loop metrics (names are a contract: the keys of ``summary.json``, schema hwpts.control/1).

All speed errors are of the true (noise-free) motor A speed, in % of the set-point. A metric that
does not apply to a scenario is None (null in JSON).
"""

from __future__ import annotations

import numpy as np

from hwpts.control.loop import LoopResult
from hwpts.control.scenarios import Scenario

BAND_PERCENT = 1.0
"""Settling band of a set-point step [% of the set-point]."""
RECOVERY_BAND_PERCENT = 0.5
"""A disturbance is recovered when the speed is back within this band for good [% of the set-point]."""
REVERSAL_MIN_V = 1e-4
"""Command moves smaller than this [V] neither count as a move nor as a reversal."""

METRIC_NAMES = ("rms_error_percent", "max_error_percent", "within_1_percent_share", "within_0_5_percent_share",
                "settling_time_s", "overshoot_percent", "peak_deviation_percent", "recovery_time_s",
                "valve_travel_v", "valve_reversals", "mode_switches_per_min", "step_time_ms")


def _time_until_within(t, err, start, stop, band):
    """Time after ``start`` from which |err| stays within band until ``stop`` (None if never)."""
    idx = np.nonzero((t >= start) & (t < stop))[0]
    if idx.size == 0:
        return None
    outside = np.abs(err[idx]) > band
    if not outside.any():
        return 0.0
    last = idx[np.nonzero(outside)[0][-1]]
    if last == idx[-1]:
        return None
    return float(t[last + 1] - start)


def reversals(command: np.ndarray) -> int:
    """Number of direction changes of the valve ``command`` [V] (steps smaller than the reversal threshold ignored)."""
    d = np.diff(command)
    d = d[np.abs(d) > REVERSAL_MIN_V]
    return int(np.sum(np.sign(d[1:]) != np.sign(d[:-1]))) if d.size > 1 else 0


def compute_metrics(scenario: Scenario, result: LoopResult, has_modes: bool) -> dict:
    """The control metrics of one closed-loop run (schema ``hwpts.control/1``): RMS and maximum error [% of set-point], time within +-1 % and +-0.5 %, settling, peak deviation, recovery, valve travel and reversals, mode switches, controller time."""
    t = result["time_s"]
    sp = result["setpoint_rpm"]
    y = result["motor_a_speed_rpm"]
    err = (y - sp) / sp * 100.0
    reach = result["reachable"] > 0.5
    m = {k: None for k in METRIC_NAMES}
    if reach.any():
        e = err[reach]
        m["rms_error_percent"] = float(np.sqrt(np.mean(e**2)))
        m["max_error_percent"] = float(np.max(np.abs(e)))
        m["within_1_percent_share"] = float(np.mean(np.abs(e) <= 1.0))
        m["within_0_5_percent_share"] = float(np.mean(np.abs(e) <= 0.5))
    events = [e for e in scenario.events_s if e < t[-1]]  # a shortened record may end before an event
    ends = events[1:] + [t[-1] + 1.0]
    if scenario.kind == "setpoint":
        settle, over = [], []
        for k, (at, stop) in enumerate(zip(events, ends)):
            i = int(np.searchsorted(t, at))
            before, after = sp[max(i - 1, 0)], sp[i]
            step = after - before
            window = (t >= at) & (t < stop)
            s = _time_until_within(t, err, at, stop, BAND_PERCENT)
            settle.append(np.inf if s is None else s)
            beyond = (y[window] - after) * np.sign(step)
            over.append(max(0.0, float(beyond.max())) / abs(step) * 100.0)
        if events:
            m["settling_time_s"] = None if not np.all(np.isfinite(settle)) else float(max(settle))
            m["overshoot_percent"] = float(max(over))
    if scenario.kind in ("disturbance", "low-wind"):
        peaks, recs = [], []
        for at, stop in zip(events, ends):
            window = (t >= at) & (t < stop)
            if scenario.kind == "disturbance":
                peaks.append(float(np.max(np.abs(err[window]))))
            r = _time_until_within(t, err, at, stop, RECOVERY_BAND_PERCENT)
            recs.append(np.inf if r is None else r)
        if peaks:
            m["peak_deviation_percent"] = float(max(peaks))
        if scenario.kind == "low-wind" and events:
            # the peak after the wind returns: an overshoot here is what a wound-up integrator does
            window = t >= scenario.events_s[0]
            m["peak_deviation_percent"] = float(np.max(np.maximum(err[window], 0.0)))
        if events:
            m["recovery_time_s"] = None if not np.all(np.isfinite(recs)) else float(max(recs))
    u = result["valve_command_v"]
    m["valve_travel_v"] = float(np.sum(np.abs(np.diff(u))))
    m["valve_reversals"] = reversals(u)
    if has_modes:
        switches = int(np.sum(np.diff(result["region"]) != 0))
        m["mode_switches_per_min"] = float(switches / ((t[-1] - t[0]) / 60.0))
    st = result.step_time_ms
    m["step_time_ms"] = {"median": float(np.median(st)), "max": float(np.max(st))}
    return m
