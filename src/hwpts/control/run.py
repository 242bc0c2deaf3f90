"""One scenario, several controllers: the closed loops, their metrics and the summary (schema
``hwpts.control/1``, a contract)."""

from __future__ import annotations

import math

import numpy as np

from hwpts.control.controllers import MODEL_BASED, make_controller
from hwpts.control.loop import REACHABLE_HOLD_S, reachable_mask, run_loop
from hwpts.control.metrics import compute_metrics
from hwpts.control.model import ModelBank
from hwpts.control.scenarios import SAMPLE_TIME_S, build_scenario
from hwpts.errors import DataError, ParameterError

SCHEMA = "hwpts.control/1"
SETPOINT_RANGE_RPM = (300.0, 1400.0)
"""Set-points the test bed can hold at some pump speed of the turbine's range [r/min]."""


def check_setpoint(bank: ModelBank, setpoint: float, output_range=None, argument: str = "--setpoint") -> None:
    """Refuse a set-point [r/min] outside the documented range or outside what the model was identified on."""
    lo, hi = SETPOINT_RANGE_RPM
    if output_range is not None:
        if output_range[1] < lo or output_range[0] > hi:  # (said as "a speed in 300-25 r/min")
            raise DataError(f"--model: the model was identified on outputs of {output_range[0]:.4g} to "
                            f"{output_range[1]:.4g}, none within the test bed's set-points {lo:.0f}-{hi:.0f} r/min; "
                            f"is its output motor A's speed in r/min?")
        lo, hi = max(lo, output_range[0]), min(hi, output_range[1])
    if not (math.isfinite(setpoint) and lo <= setpoint <= hi):
        raise ParameterError(f"{argument}: expected a speed in {lo:.0f}-{hi:.0f} r/min (within the test bed's reach "
                             f"and the model's training range), got {setpoint:g}")


def run_scenario(bank: ModelBank, half_width: float, scenario_name: str, controller_names, seed: int = 0,
                 setpoint: float = 1000.0, duration: float | None = None, model_source: str = "",
                 progress=None):
    """Run every controller on the scenario; returns (summary dict, {name: LoopResult})."""
    scenario = build_scenario(scenario_name, seed=seed, setpoint=setpoint, duration=duration)
    reach = reachable_mask(scenario)
    runs, metrics = {}, {}
    for i, name in enumerate(controller_names):
        controller = make_controller(name, bank, half_width, scenario, SAMPLE_TIME_S)
        sub = None if progress is None else (lambda f, i=i: progress((i + f) / len(controller_names), name))
        result = run_loop(scenario, controller, seed=seed, reachable=reach, progress=sub)
        runs[name] = result
        metrics[name] = compute_metrics(scenario, result, controller.has_modes)
    candidates = [n for n in controller_names if n.removesuffix("-no-inverse") in MODEL_BASED
                  and metrics[n]["rms_error_percent"] is not None]
    best = min(candidates, key=lambda n: metrics[n]["rms_error_percent"]) if candidates else None
    summary = {
        "schema": SCHEMA,
        "scenario": scenario.name,
        "seed": int(seed),
        "setpoint_rpm": float(setpoint),
        "best": best,
        "controllers": metrics,
        "description": scenario.description,
        "sample_time_s": SAMPLE_TIME_S,
        "reachable_hold_s": REACHABLE_HOLD_S,
        "reachable_share": float(np.mean(reach)),
        "model": {"source": model_source, "n_regions": bank.n_regions, "sample_time_s": bank.sample_time,
                  "hysteresis_half_width_v": half_width, "input_names": list(bank.input_names),
                  "regions": [{"region": d.region + 1, "valve_gain_rpm_per_v": _num(d.valve_gain_rpm_per_v),
                               "pump_gain": _num(d.pump_gain), "time_constant_s": _num(d.time_constant_s),
                               "used_for_control": d.region in bank.control_regions} for d in bank.designs]},
        "plant": {"generator_slip_gain_nms_per_rad": scenario.parameters.generator_slip_gain,
                  "hysteresis_half_width_v": scenario.parameters.hysteresis_half_width,
                  "droop_gain": scenario.parameters.droop_gain, "sensor_noise_std_rpm": 2.0},
    }
    if best is not None and "pi" in metrics and metrics["pi"]["rms_error_percent"]:
        summary["rms_reduction_vs_pi_percent"] = round(
            100.0 * (1.0 - metrics[best]["rms_error_percent"] / metrics["pi"]["rms_error_percent"]), 2)
    return summary, runs, scenario


def _num(x):
    return float(x) if math.isfinite(x) else None
